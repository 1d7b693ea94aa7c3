// Where subcommands look when the command line names no game folder (--base) or, for `cohort bench
// balance --real`, no scene: the bundled test map (tools/testmap builds it).
#pragma once

#include <string>
#include <vector>

namespace cohort::app {

// Relative to the working directory, as the help texts show them.
constexpr const char* kTestMapBase = "assets/testmap";
constexpr const char* kTestMapFile = "assets/testmap/maps/testmap.map";

// `given` when it names any folder; otherwise the test map's folder, looked for under the working
// directory and then under the source tree this binary was built from (so `cohort` runs from any
// folder of a checkout); otherwise no folder at all.
std::vector<std::string> bases_or_test_map(const std::vector<std::string>& given);

}  // namespace cohort::app
