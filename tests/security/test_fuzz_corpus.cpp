// Replays every input under tests/fuzz_corpus/<target>/ through the same entry points the
// libFuzzer targets use (fuzz/src/entry_points.hpp), built with the project's compiler. An input
// may be accepted or rejected with the reader's own exception (CsvError, ConfigError); any
// other exception, a broken invariant, or a sanitizer report (in the -DBBW_SANITIZE=ON CI run)
// fails. Files named accept_* must be accepted and reject_* rejected, so the harness itself is
// checked: the real configs load, the regressions found by fuzzing stay refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

#include "entry_points.hpp"

namespace bbw::fuzz {
// Test names and failure messages show the target's name.
inline void PrintTo(const Target& t, std::ostream* os) { *os << t.name; }
}  // namespace bbw::fuzz

namespace {

namespace fs = std::filesystem;

std::string source_dir() {
  const char* s = std::getenv("BBW_SOURCE_DIR");
  return s != nullptr ? s : BBW_TEST_SOURCE_DIR;
}

std::vector<fs::path> corpus(const std::string& target) {
  std::vector<fs::path> files;
  const fs::path dir = fs::path(source_dir()) / "tests" / "fuzz_corpus" / target;
  if (!fs::is_directory(dir)) return files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file()) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

class FuzzCorpus : public ::testing::TestWithParam<bbw::fuzz::Target> {};

TEST_P(FuzzCorpus, EveryInputIsAcceptedOrRejectedCleanly) {
  const bbw::fuzz::Target& target = GetParam();
  const auto files = corpus(target.name);
  ASSERT_FALSE(files.empty()) << "no corpus in tests/fuzz_corpus/" << target.name;
  int accepted = 0, rejected = 0, labelled = 0;
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
    bbw::fuzz::Outcome outcome{};
    try {
      outcome = target.run(data, bytes.size(), source_dir());
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": escaped with " << typeid(e).name() << ": " << e.what();
      continue;
    }
    (outcome == bbw::fuzz::Outcome::Accepted ? accepted : rejected)++;
    const std::string name = f.filename().string();
    if (name.rfind("accept_", 0) == 0) {
      ++labelled;
      EXPECT_EQ(outcome, bbw::fuzz::Outcome::Accepted) << f << " must be accepted";
    } else if (name.rfind("reject_", 0) == 0) {
      ++labelled;
      EXPECT_EQ(outcome, bbw::fuzz::Outcome::Rejected) << f << " must be rejected";
    }
  }
  EXPECT_GT(labelled, 0);
  RecordProperty("accepted", accepted);
  RecordProperty("rejected", rejected);
  std::printf("%s: %zu inputs, %d accepted, %d rejected\n", target.name, files.size(), accepted, rejected);
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzCorpus, ::testing::ValuesIn(bbw::fuzz::targets()),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(FuzzCorpus, HarnessFindsABrokenInvariant) {
  // The entry points are not vacuous: a well-formed table is accepted, a hostile one rejected,
  // and bytes that are not text at all never escape as anything but a rejection.
  const std::string good = "t_s,x\n0,1\n";
  const std::string bad = "t_s,x\n0,nan\n";
  const std::string junk("\x00\xff\xfe\n,,\x01", 7);
  auto run = [](const std::string& s) {
    return bbw::fuzz::csv(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
  };
  EXPECT_EQ(run(good), bbw::fuzz::Outcome::Accepted);
  EXPECT_EQ(run(bad), bbw::fuzz::Outcome::Rejected);
  EXPECT_EQ(run(junk), bbw::fuzz::Outcome::Rejected);
}

}  // namespace
