// autograsp-bench --approaching: the table of approaching grasps (eval/approaching.h), split by
// whether the open hand was already inside the object, with the whole hand's penetration after
// the grasp, how far the strategy moved the hand and the contacts per grasp.
#pragma once

#include <cstdio>
#include <vector>

#include "run_mesh.h"

namespace sdfg::bench {

// Writes one markdown table: per mesh and method, three lines (all grasps, open hand inside,
// open hand clear); the last column counts the grasps whose hand needed more than the
// clearance's bound and was left where it was.
void printApproachingTable(std::FILE* out, const std::vector<Row>& rows);

}  // namespace sdfg::bench
