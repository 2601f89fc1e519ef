// mft-space: the offline MFT preferable space of the five-bar legs (paper sec. III-B, docs/reference/five-bar-theory.md#the-polygon-fit).
// Exit codes: 0 done, 1 the work failed (fit, file output, figure on `figure`), 2 bad arguments or bad config.
#include <iostream>
#include <string>

#include "cli_args.hpp"
#include "common/strict_yaml.hpp"
#include "common/tool_io.hpp"
#include "space_commands.hpp"

using namespace mft::tools;

namespace {

const char* kUsage = R"(usage: mft-space <command> [options]

commands
  fit      grid the leg's reachable space, fit the conservative polygon, write the polytope YAML
  figure   draw the paper's Fig. 5 (PNG) for a stored polytope
  stance   LTI, RACI and polygon membership along the vertical stance
  index    LTI (input/output indices) and RACI of one configuration
  all      fit + figure + stance table into --out DIR (mft_space.yaml, mft_space.png, stance.txt)
  violation  the paper's (10) per row of a CSV of joint angles (mft-export's gt_q.csv): each leg's and the
           augmented polytope's max(A q - b) [rad], <= 0 inside

common options
  --robot FILE        robot description (default: <config>/robot.yaml)
  --json              machine-readable output on stdout (progress stays on stderr)
  --quiet             no progress on stderr

fit / all
  --output FILE       polytope YAML (fit default: <config>/mft_space.yaml; all: also DIR/mft_space.yaml)
  --out DIR           (all) output folder, created if missing
  --joint-step RAD    joint-space grid step (default 0.01)
  --cart-step M       Cartesian grid step (default 0.01 = the paper's 10 x 10 mm)
  --edges N           polygon edges (default 6; only a hexagon gives the WBC's 12 x 4 polytope)
  --starts N          random starts of the fit (default 24)   --seed N   RNG seed (default 1)
index / fit / all (thresholds and RACI)
  --lti-min X --lti-max X      LTI range (default 0.7 .. 1)
  --raci-min X --raci-max X    RACI range in N/sqrt(kg) (default 0 .. T_m,max/sqrt(J_m) of the actuator)
  --accel A           desired foot acceleration bound a_max (default 60 m/s^2)
  --raci-form F       optimal (default, optimal gear ratio) or fixed (k = n sqrt(J_m) of the actuator)
  --drive-k K         override k for the fixed form       --gravity   include gravity in RACI
figure / stance
  --polytope FILE     stored polytope (default: <config>/mft_space.yaml)
  --png FILE          (figure) output PNG (default mft_space.png)
  --from M --to M --step M     (stance) base heights (default 0.38 .. 0.46 step 0.01)
index
  --rear Q4 --fore Q6 actuated hip angles [rad] (required)
violation
  --csv FILE          input CSV with the columns q4, q6, q8, q10 (required; stamp_ns, time_s, tick pass through)
  --polytope FILE     stored polytope (default: <config>/mft_space.yaml)
  --output FILE       write the CSV here (default: standard output; --json then prints a summary)
)";

// kUsage with <config> replaced by the configuration folder.
std::string usage() {
  std::string text = kUsage;
  const std::string token = "<config>";
  for (std::size_t at = text.find(token); at != std::string::npos; at = text.find(token, at))
    text.replace(at, token.size(), configDir());
  return text;
}

}  // namespace

static int toolMain(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "mft-space: missing command\n" << usage();
    return 2;
  }
  const std::string cmd = argv[1];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    std::cout << usage();
    return 0;
  }
  try {
    if (cmd == "fit") return cmdFit(argc, argv);
    if (cmd == "figure") return cmdFigure(argc, argv);
    if (cmd == "stance") return cmdStance(argc, argv);
    if (cmd == "index") return cmdIndex(argc, argv);
    if (cmd == "all") return cmdAll(argc, argv);
    if (cmd == "violation") return cmdViolation(argc, argv);
    std::cerr << "mft-space: unknown command '" << cmd << "' (fit, figure, stance, index, all, violation; see --help)\n";
    return 2;
  } catch (const UsageError& e) {
    std::cerr << "mft-space " << cmd << ": " << e.what() << "\n";
    return 2;
  } catch (const mft::config::ConfigError& e) {
    std::cerr << "mft-space " << cmd << ": bad configuration: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "mft-space " << cmd << ": " << e.what() << "\n";
    return 1;
  }
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-space", [&] { return toolMain(argc, argv); });
}
