// Hostile inputs to the strict YAML reader and the CSV reader, found by fuzzing and review
// (issue 7, docs/security.md): duplicate and non-scalar keys, paths that are not regular files
// (a directory made yaml-cpp throw std::ios_base::failure past the reader; a FIFO would block),
// oversized files and texts. Each is refused with a specific message.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>

#include "bbw/common/csv.hpp"
#include "bbw/common/strict_yaml.hpp"

namespace {

using bbw::config::ConfigError;
using bbw::config::Reader;

class TempDir {
 public:
  TempDir() {
    std::string t = (std::filesystem::temp_directory_path() / "bbw_hostile_XXXXXX").string();
    if (::mkdtemp(t.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    dir_ = t;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

 private:
  std::filesystem::path dir_;
};

// If a reader did block on a FIFO, a writer that opens and closes it lets the reader see EOF, so
// a failing test ends instead of hanging in the future's destructor.
void unblock_fifo(const std::string& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK);
  if (fd >= 0) ::close(fd);
}

template <class F>
std::string config_rule(F f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.rule() + " @" + std::to_string(e.line()) + " " + e.key_path();
  }
  return "<no ConfigError>";
}

TEST(HostileYaml, DuplicateKeysAreRejectedWithTheirLineAndPath) {
  EXPECT_EQ(config_rule([] { Reader::from_string("mode: paper\ngain: 1\nmode: robust\n", "d.yaml"); }),
            "duplicate key @3 mode");
  // Nested: detected when the loader opens that mapping.
  auto r = Reader::from_string("range:\n  x_min_rev: 0\n  x_min_rev: 5\n", "n.yaml");
  EXPECT_EQ(config_rule([&] { r.map("range"); }), "duplicate key @3 range.x_min_rev");
  // In a list of mappings.
  auto l = Reader::from_string("corners:\n  - name: FL\n    name: FR\n", "l.yaml");
  EXPECT_EQ(config_rule([&] { l.maps("corners"); }), "duplicate key @3 corners[0].name");
}

TEST(HostileYaml, NonScalarKeysAreRejected) {
  EXPECT_EQ(config_rule([] { Reader::from_string("? [a, b]\n: 1\n", "k.yaml"); }).rfind("keys must be plain names", 0),
            0u);
  EXPECT_EQ(config_rule([] { Reader::from_string("{a: 1}: 2\n", "k.yaml"); }).rfind("keys must be plain names", 0), 0u);
}

TEST(HostileYaml, DirectoriesFifosAndHugeFilesAreRefused) {
  TempDir tmp;
  std::filesystem::create_directory(tmp.path("dir.yaml"));
  EXPECT_EQ(config_rule([&] { Reader::from_file(tmp.path("dir.yaml")); }), "is not a regular file @0 ");

  // A FIFO with no writer: opening it would block forever. The check returns at once.
  ASSERT_EQ(::mkfifo(tmp.path("fifo.yaml").c_str(), 0600), 0);
  auto fifo = std::async(std::launch::async, [&] { return config_rule([&] { Reader::from_file(tmp.path("fifo.yaml")); }); });
  if (fifo.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    unblock_fifo(tmp.path("fifo.yaml"));
    FAIL() << "from_file blocked on a FIFO";
  }
  EXPECT_EQ(fifo.get(), "is not a regular file @0 ");

  {
    std::ofstream big(tmp.path("big.yaml"));
    const std::string line = "# " + std::string(1021, 'x') + "\n";
    for (int i = 0; i < 5 * 1024; ++i) big << line;  // 5 MiB of comments
    big << "a: 1\n";
  }
  EXPECT_EQ(config_rule([&] { Reader::from_file(tmp.path("big.yaml")); }).rfind("file is 5242885 bytes, more than the limit", 0),
            0u);
  EXPECT_EQ(config_rule([] { Reader::from_string(std::string(5u << 20, '#'), "big"); }).rfind("text is", 0), 0u);
  EXPECT_EQ(config_rule([] { Reader::from_file("/dev/null"); }), "is not a regular file @0 ");
}

TEST(HostileYaml, DeepNestingIsASyntaxErrorNotAStackOverflow) {
  const std::string deep = "a: " + std::string(100000, '[') + std::string(100000, ']') + "\n";
  EXPECT_NE(config_rule([&] { Reader::from_string(deep, "deep.yaml"); }).find("YAML syntax error"), std::string::npos);
}

TEST(HostileCsv, FifosAndDevicesAreRefused) {
  TempDir tmp;
  ASSERT_EQ(::mkfifo(tmp.path("fifo.csv").c_str(), 0600), 0);
  bbw::csv::ReadOptions o;
  o.required = {"t"};
  auto read = [&](const std::string& file) -> std::string {
    try {
      bbw::csv::read(file, o);
    } catch (const bbw::csv::CsvError& e) {
      return e.what();
    }
    return "<no CsvError>";
  };
  auto fifo = std::async(std::launch::async, [&] { return read(tmp.path("fifo.csv")); });
  if (fifo.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    unblock_fifo(tmp.path("fifo.csv"));
    FAIL() << "csv::read blocked on a FIFO";
  }
  EXPECT_EQ(fifo.get(), tmp.path("fifo.csv") + ": is not a regular file");
  EXPECT_EQ(read("/dev/zero"), "/dev/zero: is not a regular file");
}

}  // namespace
