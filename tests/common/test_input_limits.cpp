// Inputs that cannot exhaust the machine, and one CSV reader for every tool (issue 17; the
// limits and the tests that pin them are listed in docs/security.md, "Inputs"):
//   YAML: node count with aliases expanded, entries per list, nesting, characters of values;
//   CSV: byte-order mark, quoted headers, duplicate names, time that does not increase, line
//   length, non-printable bytes in messages, file kinds (read_header too);
//   plots: a failing gnuplot names the script and leaves no PNG; gnuplot dies with its parent.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>
#include <string>
#include <thread>

#include "bbw/common/csv.hpp"
#include "bbw/common/plot.hpp"
#include "bbw/common/strict_yaml.hpp"

namespace {

using bbw::config::ConfigError;
using bbw::config::Reader;
using bbw::csv::CsvError;
using bbw::csv::ReadOptions;
using Clock = std::chrono::steady_clock;

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    std::string t = (fs::temp_directory_path() / "bbw_limits_XXXXXX").string();
    if (::mkdtemp(t.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    dir_ = t;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

 private:
  fs::path dir_;
};

template <class F>
std::string config_error(F f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no ConfigError>";
}

template <class F>
std::string csv_error(F f) {
  try {
    f();
  } catch (const CsvError& e) {
    return e.what();
  }
  return "<no CsvError>";
}

// The file: one 20 000-entry list aliased 1000 times (about 44 KB of YAML... plus the
// list itself), as a scenario's local_loops levels.
std::string alias_bomb(std::size_t entries, std::size_t uses) {
  std::ostringstream y;
  y << "name: bomb\nseed: 1\nduration_s: 2\nplant: ../plant/ecaliper.yaml\nlevels: &L [";
  for (std::size_t i = 0; i < entries; ++i) y << (i ? "," : "") << (i % 10);
  y << "]\ncorners:\n  - name: FL\n    temperature_C: 20\n    drive:\n      mode: position\n      segments:\n";
  for (std::size_t i = 0; i < uses; ++i) {
    y << "        - {type: local_loops, levels_rev: *L, amplitude_rev: 0.1, period_s: 1}\n";
  }
  return y.str();
}

TEST(InputLimitsYaml, AliasAmplificationIsRefusedQuicklyWithItsLine) {
  const std::string text = alias_bomb(20000, 1000);
  const auto t0 = Clock::now();
  const std::string e = config_error([&] { Reader::from_string(text, "bomb.yaml"); });
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_NE(e.find("more than 200000 nodes when its aliases are expanded"), std::string::npos) << e;
  EXPECT_EQ(e.rfind("bomb.yaml:", 0), 0u) << e;
  EXPECT_NE(e.find("corners[0].drive.segments["), std::string::npos) << e;  // where the budget ran out
  EXPECT_LT(s, 5.0) << "took " << s << " s";  // was 12.6 s and 1.79 GB in the loader
  // The same list used a few times is fine.
  EXPECT_NO_THROW(Reader::from_string(alias_bomb(20000, 5), "few.yaml"));
}

TEST(InputLimitsYaml, LongListsAndWideMappingsAreRefused) {
  std::string list = "x: [";
  for (int i = 0; i <= 20000; ++i) list += (i ? ",1" : "1");
  list += "]\n";
  EXPECT_NE(config_error([&] { Reader::from_string(list, "l.yaml"); })
                .find("l.yaml:1: key 'x': list has 20001 entries, more than the limit of 20000"),
            std::string::npos);
  bbw::config::DocumentLimits tight;
  tight.max_list_entries = 3;
  EXPECT_NE(config_error([&] { Reader::from_string("a: 1\nb: 2\nc: 3\nd: 4\n", "m.yaml", tight); })
                .find("mapping has 4 keys, more than the limit of 3"),
            std::string::npos);
  EXPECT_NO_THROW(Reader::from_string("a: 1\nb: 2\nc: 3\n", "m.yaml", tight));
}

TEST(InputLimitsYaml, DeepNestingAndScalarVolumeAreRefused) {
  std::string deep = "a: ";
  for (int i = 0; i < 70; ++i) deep += "[";
  for (int i = 0; i < 70; ++i) deep += "]";
  EXPECT_NE(config_error([&] { Reader::from_string(deep + "\n", "d.yaml"); }).find("nested deeper than 64 levels"),
            std::string::npos);
  // 4 KB of text used 5000 times: 20 MB of values for a reader that copies them.
  std::string text = "s: &s " + std::string(4096, 'x') + "\nl: [";
  for (int i = 0; i < 5000; ++i) text += (i ? ", *s" : "*s");
  text += "]\n";
  EXPECT_NE(config_error([&] { Reader::from_string(text, "s.yaml"); }).find("characters of values"), std::string::npos);
}

TEST(InputLimitsYaml, FromFileAppliesTheLimitsToo) {
  TempDir tmp;
  {
    std::ofstream f(tmp.path("bomb.yaml"));
    f << alias_bomb(20000, 1000);
  }
  EXPECT_NE(config_error([&] { Reader::from_file(tmp.path("bomb.yaml")); }).find("aliases are expanded"),
            std::string::npos);
}

// --- CSV ---

bbw::csv::Table read_text(const std::string& text, ReadOptions o) {
  std::istringstream in(text);
  return bbw::csv::read_stream(in, "t.csv", o);
}

TEST(InputLimitsCsv, ByteOrderMarkAndQuotedHeadersAreAccepted) {
  ReadOptions o;
  o.required = {"time_s", "x"};
  const auto t = read_text("\xEF\xBB\xBFtime_s,x\n0,1\n1,2\n", o);
  EXPECT_EQ(t.rows(), 2u);
  const auto q = read_text("\"time_s\", \"x\" ,\"a,b\"\n0,\"1.5\",3\n", o);
  EXPECT_DOUBLE_EQ(q.column("x")[0], 1.5);
  std::istringstream h("\xEF\xBB\xBF\"a,b\",\"say \"\"hi\"\"\"\n");
  EXPECT_EQ(bbw::csv::read_header_stream(h, "h.csv"), (std::vector<std::string>{"a,b", "say \"hi\""}));
  // A quote left open is the header's error, or a data line's rejection.
  EXPECT_NE(csv_error([&] { read_text("\"time_s,x\n0,1\n", o); }).find("t.csv:1: header: quote opened at column 1"),
            std::string::npos);
  const auto r = read_text("time_s,x\n0,1\n1,\"2\n2,3\n", o);
  EXPECT_EQ(r.lines_rejected, 1u);
  EXPECT_EQ(r.first_rejected_lines.at(0), 3u);
  EXPECT_EQ(csv_error([&] { read_text("\xFF\xFEt\0i", o); }).rfind("t.csv:1: UTF-16 text", 0), 0u);
}

TEST(InputLimitsCsv, DuplicateColumnNamesAreRefused) {
  ReadOptions o;
  o.required = {"t"};
  EXPECT_EQ(csv_error([&] { read_text("t,x,\"x\"\n0,1,2\n", o); }),
            "t.csv:1: column 'x' appears twice in the header (fields 2 and 3)");
  EXPECT_EQ(csv_error([&] { read_text("\n\nt,t\n0,1\n", o); }),
            "t.csv:3: column 't' appears twice in the header (fields 1 and 2)");
  // Wide headers: at most 1024 columns by default.
  std::string wide = "t";
  for (int i = 1; i < 1024; ++i) wide += ",c" + std::to_string(i);  // 1024 columns
  EXPECT_EQ(csv_error([&] { read_text(wide + ",c1024\n", o); }),
            "t.csv:1: header has 1025 columns, more than the limit of 1024");
  EXPECT_EQ(read_text(wide + "\n1" + std::string(1023, ',') + "\n", o).rows(), 1u);
}

TEST(InputLimitsCsv, TimeThatDoesNotIncreaseIsRefusedWithItsLineOrDroppedWhenAllowed) {
  ReadOptions o;
  o.required = {"t", "x"};
  o.time_column = "t";
  const std::string text = "t,x\n0,1\n0.1,1\nnan,1\n0.1,2\n0.05,3\n0.2,4\n";
  EXPECT_EQ(csv_error([&] { read_text(text, o); }),
            "t.csv:5: time 't' does not increase: 0.1 after 0.1 on line 3 (sort the file, or allow dropping such "
            "lines: --allow-unsorted-time)");
  o.allow_unsorted_time = true;
  const auto t = read_text(text, o);
  EXPECT_EQ(t.column("t"), (std::vector<double>{0, 0.1, 0.2}));
  EXPECT_EQ(t.lines_unsorted_time, 2u);
  EXPECT_EQ(t.first_unsorted_time_line, 5u);
  EXPECT_EQ(t.lines_rejected, 1u);
  EXPECT_NE(t.rejection_summary().find("dropped 2 whose time did not increase (first: line 5)"), std::string::npos);
  o.time_column = "nope";
  EXPECT_NE(csv_error([&] { read_text(text, o); }).find("time column 'nope' is not loaded"), std::string::npos);
}

TEST(InputLimitsCsv, NonPrintableBytesAreEscapedInMessages) {
  ReadOptions o;
  o.required = {"t"};
  const std::string e = csv_error([&] { read_text(std::string("\x01\x7f\xff\x1b[2J,y\n1,2\n"), o); });
  EXPECT_NE(e.find("header has: \\x01\\x7F\\xFF\\x1B[2J, y"), std::string::npos) << e;
  for (const char c : e) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "byte " << static_cast<int>(static_cast<unsigned char>(c));
  const auto t = read_text("t\n\x1b]0;x\x07\n1\n", o);
  EXPECT_EQ(t.first_rejected_reasons.at(0), "not a number '\\x1B]0;x\\x07' in 't'");
  EXPECT_EQ(bbw::csv::printable(std::string(100, 'a'), 4), "aaaa...");
}

TEST(InputLimitsCsv, LongLinesAreBoundedAndTheHeaderLineIsAnError) {
  ReadOptions o;
  o.required = {"t"};
  o.max_line_chars = 16;
  EXPECT_EQ(csv_error([&] { read_text(std::string(1000, 'a') + "\n1\n", o); }),
            "t.csv:1: header line is longer than 16 characters");
  const auto t = read_text("t\n" + std::string(1 << 20, '1') + "\n2\n", o);
  EXPECT_EQ(t.rows(), 1u);
  EXPECT_EQ(t.first_rejected_reasons.at(0), "longer than 16 characters");
}

TEST(InputLimitsCsv, ReadHeaderRefusesWhatIsNotARegularFileWithoutBlocking) {
  TempDir tmp;
  ASSERT_EQ(::mkfifo(tmp.path("fifo.csv").c_str(), 0600), 0);
  fs::create_directory(tmp.path("dir.csv"));
  auto header = [](const std::string& f) { return csv_error([&] { bbw::csv::read_header(f); }); };
  auto fifo = std::async(std::launch::async, [&] { return header(tmp.path("fifo.csv")); });
  if (fifo.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    const int fd = ::open(tmp.path("fifo.csv").c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
    FAIL() << "read_header blocked on a FIFO";
  }
  EXPECT_EQ(fifo.get(), tmp.path("fifo.csv") + ": is not a regular file");
  EXPECT_EQ(header("/dev/zero"), "/dev/zero: is not a regular file");
  EXPECT_EQ(header(tmp.path("dir.csv")), tmp.path("dir.csv") + ": is a directory, not a CSV file");
  {
    std::ofstream f(tmp.path("q.csv"));
    f << "\xEF\xBB\xBF\"time_s\",\"x\"\n0,1\n";
  }
  EXPECT_EQ(bbw::csv::read_header(tmp.path("q.csv")), (std::vector<std::string>{"time_s", "x"}));
}

// --- plots ---

bool gnuplot_available() { return std::system("gnuplot --version >/dev/null 2>&1") == 0; }

TEST(Plot, AFailingScriptNamesWhatFailedAndLeavesNoPng) {
  // gnuplot is a dependency ./bbw setup installs (gnuplot-nox): its absence is a failure, not a skip.
  ASSERT_TRUE(gnuplot_available()) << "gnuplot is not installed (run ./bbw setup)";
  TempDir tmp;
  const std::string png = tmp.path("a.png");
  { std::ofstream(png) << "an older plot"; }
  const std::string script = "set terminal pngcairo\nset output " + bbw::plot::quote(png) +
                             "\nplot " + bbw::plot::quote(tmp.path("missing.csv")) + " using 1:2\n";
  EXPECT_EQ(bbw::plot::outputs_of(script), std::vector<std::string>{png});
  try {
    bbw::plot::run_gnuplot(script, tmp.path("a.gp"));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("gnuplot exit 1 on " + tmp.path("a.gp")), std::string::npos) << m;
    EXPECT_NE(m.find("No data in plot"), std::string::npos) << m;  // gnuplot's own last line
    EXPECT_NE(m.find("not written: " + png), std::string::npos) << m;
  }
  EXPECT_FALSE(fs::exists(png));
  // A good script writes a non-empty PNG.
  { std::ofstream(tmp.path("d.csv")) << "0 0\n1 1\n"; }
  const std::string good = "set terminal pngcairo\nset output " + bbw::plot::quote(png) + "\nplot " +
                           bbw::plot::quote(tmp.path("d.csv")) + " using 1:2 with lines\n";
  bbw::plot::run_gnuplot(good, tmp.path("b.gp"));
  EXPECT_GT(fs::file_size(png), 1000u);
}

TEST(Plot, GnuplotDiesWithItsParent) {
  // gnuplot is a dependency ./bbw setup installs (gnuplot-nox): its absence is a failure, not a skip.
  ASSERT_TRUE(gnuplot_available()) << "gnuplot is not installed (run ./bbw setup)";
  TempDir tmp;
  const std::string pid_file = tmp.path("gnuplot.pid");
  // The script records gnuplot's pid (the shell's parent) and then waits for a minute.
  const std::string script = "system('echo $PPID > " + pid_file + ".tmp && mv " + pid_file + ".tmp " + pid_file +
                             "')\npause 60\n";
  const pid_t tool = ::fork();
  ASSERT_GE(tool, 0);
  if (tool == 0) {
    try {
      bbw::plot::run_gnuplot(script, tmp.path("wait.gp"));
    } catch (...) {
    }
    ::_exit(0);
  }
  pid_t gnuplot = 0;
  for (const auto deadline = Clock::now() + std::chrono::seconds(20); Clock::now() < deadline && gnuplot == 0;) {
    std::ifstream f(pid_file);
    if (!(f >> gnuplot)) gnuplot = 0;
    if (gnuplot == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polled with a deadline
  }
  ASSERT_GT(gnuplot, 0) << "gnuplot did not start";
  ASSERT_EQ(::kill(gnuplot, 0), 0);
  ::kill(tool, SIGKILL);
  int status = 0;
  ::waitpid(tool, &status, 0);
  // gnuplot is not our child: wait for it to be gone (PR_SET_PDEATHSIG sent it SIGKILL).
  bool gone = false;
  for (const auto deadline = Clock::now() + std::chrono::seconds(20); Clock::now() < deadline && !gone;) {
    std::ifstream stat("/proc/" + std::to_string(gnuplot) + "/stat");
    std::string pid, comm, state;
    gone = !(stat >> pid >> comm >> state) || state == "Z" || comm != "(gnuplot)";
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polled with a deadline
  }
  EXPECT_TRUE(gone) << "gnuplot " << gnuplot << " outlived the killed tool";
  if (!gone) ::kill(gnuplot, SIGKILL);
}

}  // namespace
