// Runs the fuzz target (scene_fuzzer.cpp) over saved inputs, without libFuzzer: each file of the
// folders on the command line and in TOYRT_FUZZ_CORPUS (colon-separated), once, in name order.
// The target's own checks abort on a broken property, so a zero exit means every input kept them.
// Built per CPU level by tests/levels (the wheels' levels each replay the corpus `make fuzz` grew).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  std::vector<std::string> folders(argv + 1, argv + argc);
  if (const char* extra = std::getenv("TOYRT_FUZZ_CORPUS")) {
    std::string list = extra;
    for (size_t start = 0; start <= list.size();) {
      const size_t end = std::min(list.find(':', start), list.size());
      if (end > start) folders.push_back(list.substr(start, end - start));
      start = end + 1;
    }
  }
  size_t inputs = 0;
  for (const std::string& folder : folders) {
    // A folder named but missing is a mistake in the caller, not an empty corpus.
    if (!fs::is_directory(folder)) {
      std::fprintf(stderr, "corpus_replay: %s is not a folder\n", folder.c_str());
      return 2;
    }
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(folder))
      if (entry.is_regular_file()) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
      std::ifstream in(file, std::ios::binary);
      const std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
      ++inputs;
    }
    std::printf("corpus_replay: %s: %zu inputs\n", folder.c_str(), files.size());
  }
  if (inputs == 0) {
    std::fprintf(stderr, "corpus_replay: no inputs\n");
    return 2;
  }
  std::printf("corpus_replay: %zu inputs, every property held\n", inputs);
  return 0;
}
