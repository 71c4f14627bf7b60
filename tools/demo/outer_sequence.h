// The demo's outer hand sequence (issue 27): a right hand reaches down into a table top and
// slides along it inside, then lifts out, as a tracked hand may when nothing stops the user's
// real hand. The engine's OuterHand (grasp/outer_hand.h), driven here frame by frame at 90 Hz,
// keeps the shown hand on the table's surface and slides it along. The picture sets the tracked
// hand (grey, top row) over the shown hand (colour, bottom row) for a few of the frames; the
// report gives, per frame, how deep each of them is in the table.
#pragma once

#include <string>

#include "renderer.h"
#include "report.h"

namespace sdfg::demo {

struct OuterSequenceOptions {
  uint32_t width = 640;  // each of the picture's panels is width / 2 square
  uint32_t supersample = 2;
  std::string outDir;
  std::string png = "outer-hand.png";
};

// Runs the sequence, renders the picture (5 columns, 2 rows of width / 2 panels, 4 px apart)
// into outDir/png and fills `report`. False with `error` when the outer hand refused a frame or
// rendering or writing failed.
bool runOuterSequence(Renderer& renderer, const OuterSequenceOptions& options, OuterReport& report,
                      std::string& error);

}  // namespace sdfg::demo
