// autograsp-bench's output: the tables it prints (the paper's Table 1 layout, quality, ratios)
// and the JSON that docs quote and --report reads.
#pragma once

#include <string>
#include <vector>

#include "bench_options.h"
#include "json_file.h"
#include "run_mesh.h"
#include "run_scenes.h"

namespace sdfg::bench {

// The run as the JSON that docs quote and --report reads: the settings, the provenance of the
// build (json_file.h), and one object per row with its figures (null where there are none).
tools::Json resultsJson(const Options& o, const std::vector<Row>& rows);
// resultsJson() into `file`; false when it cannot be written.
// With --scenes, `sceneRows` as its "scenes" array (scenesJson()); `bufferRows` (buffer
// targets, runBufferScenes()) as "buffer_targets" when there are any.
bool writeJson(const std::string& file, const Options& o, const std::vector<Row>& rows,
               const std::vector<SceneRow>& sceneRows = {},
               const std::vector<SceneRow>& bufferRows = {});
void printTables(const Options& o, const std::vector<Row>& rows);

}  // namespace sdfg::bench
