#pragma once
// mft-space's commands, one function each (argv[1] is the command; the options follow). Each throws UsageError
// for bad options and ConfigError for a bad robot or polytope file; main.cpp turns them into exit codes.
#include <string>

namespace mft::tools {

// The configuration folder of this executable: the source tree's, or <prefix>/share/mft_wbc/config installed.
std::string configDir();

int cmdFit(int argc, char** argv);
int cmdFigure(int argc, char** argv);
int cmdStance(int argc, char** argv);
int cmdIndex(int argc, char** argv);
int cmdAll(int argc, char** argv);
int cmdViolation(int argc, char** argv);

}  // namespace mft::tools
