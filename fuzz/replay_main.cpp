// Replays a fuzz target's inputs without libFuzzer, in every build (ctest -L fuzz): each file given, or each
// file of each folder given, is fed once to runOne(). A file named accept-* must be accepted and refuse-* refused;
// any other name (a crasher kept as a regression case) may be either. Anything escaping runOne is reported with
// the file's name and fails the run, as does a folder without inputs. A crash ends the process (the test fails).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_target.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputsOf(const std::vector<std::string>& args) {
  std::vector<fs::path> files;
  for (const std::string& a : args) {
    if (!fs::is_directory(a)) {
      files.emplace_back(a);
      continue;
    }
    std::vector<fs::path> in_folder;
    for (const auto& entry : fs::directory_iterator(a))
      if (entry.is_regular_file()) in_folder.push_back(entry.path());
    std::sort(in_folder.begin(), in_folder.end());
    files.insert(files.end(), in_folder.begin(), in_folder.end());
  }
  return files;
}

std::string oneLine(std::string text) {
  std::replace_if(text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  return text.size() > 200 ? text.substr(0, 200) + "..." : text;
}

// "" when the outcome is what the file's name asks for, else why not.
std::string unexpected(const std::string& name, const mft::fuzz::Outcome& o) {
  if (o.message.empty()) return "an outcome without a message";
  if (name.rfind("accept-", 0) == 0 && !o.accepted) return "refused, but its name says accept-";
  if (name.rfind("refuse-", 0) == 0 && o.accepted) return "accepted, but its name says refuse-";
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::printf("usage: %s FILE_OR_FOLDER...\nFeeds every input once to the fuzz target (no libFuzzer); files named "
                "accept-* must be accepted, refuse-* refused.\n", argv[0]);
    return argc < 2 ? 2 : 0;
  }
  int accepted = 0, refused = 0, bad = 0;
  const std::vector<fs::path> files = inputsOf(std::vector<std::string>(argv + 1, argv + argc));
  for (const fs::path& f : files) {
    std::ifstream in(f, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string name = f.filename().string();
    std::string problem;
    try {
      if (!in.good() && !in.eof()) throw std::runtime_error("cannot read the file");
      const mft::fuzz::Outcome o = mft::fuzz::runOne(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      problem = unexpected(name, o);
      if (problem.empty()) {
        ++(o.accepted ? accepted : refused);
        std::printf("%s: %s: %s\n", name.c_str(), o.accepted ? "accepted" : "refused", oneLine(o.message).c_str());
      }
    } catch (const std::exception& e) {
      problem = std::string("escaped: ") + e.what();
    } catch (...) {
      problem = "escaped: an exception that is no std::exception";
    }
    if (!problem.empty()) {
      ++bad;
      std::printf("%s: UNEXPECTED: %s\n", name.c_str(), oneLine(problem).c_str());
    }
  }
  std::printf("replayed %zu inputs: %d accepted, %d refused, %d unexpected\n", files.size(), accepted, refused, bad);
  return (bad == 0 && !files.empty()) ? 0 : 1;
}
