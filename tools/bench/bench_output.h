// autograsp-bench's output: the tables it prints (the paper's Table 1 layout, quality, ratios)
// and the JSON that docs quote and --report reads.
#pragma once

#include <string>
#include <vector>

#include "bench_options.h"
#include "run_mesh.h"

namespace sdfg::bench {

bool writeJson(const std::string& file, const Options& o, const std::vector<Row>& rows);
void printTables(const Options& o, const std::vector<Row>& rows);

}  // namespace sdfg::bench
