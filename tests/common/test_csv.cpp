#include "bbw/common/csv.hpp"

#include <gtest/gtest.h>

#include <sstream>

using bbw::csv::CsvError;
using bbw::csv::ReadOptions;

TEST(Csv, ReadsRequiredAndOptionalColumns) {
  std::istringstream in("time_s,position_rev,force_internal_kN,extra\n0,1,2,9\n0.001,1.1,2.1,9\n");
  ReadOptions o;
  o.required = {"time_s", "position_rev", "force_internal_kN"};
  o.optional = {"force_external_kN", "extra"};
  const auto t = bbw::csv::read_stream(in, "mem.csv", o);
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_TRUE(t.has("extra"));
  EXPECT_FALSE(t.has("force_external_kN"));
  EXPECT_DOUBLE_EQ(t.column("position_rev")[1], 1.1);
}

TEST(Csv, RejectsBadLinesWithCountsAndLineNumbers) {
  std::istringstream in("a,b\n1,2\nnan,3\n4,inf\n5,x\n6\n7,8\n");
  ReadOptions o;
  o.required = {"a", "b"};
  const auto t = bbw::csv::read_stream(in, "bad.csv", o);
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.lines_rejected, 4u);
  ASSERT_EQ(t.first_rejected_lines.size(), 4u);
  EXPECT_EQ(t.first_rejected_lines[0], 3u);
  EXPECT_EQ(t.first_rejected_reasons[0], "NaN in 'a'");
  EXPECT_EQ(t.first_rejected_reasons[1], "infinite in 'b'");
  EXPECT_EQ(t.first_rejected_lines[3], 6u);
  EXPECT_NE(t.rejection_summary().find("rejected 4 of 6"), std::string::npos);
}

TEST(Csv, NoUsableDataIsAnError) {
  std::istringstream in("a,b\nnan,1\n");
  ReadOptions o;
  o.required = {"a", "b"};
  EXPECT_THROW(bbw::csv::read_stream(in, "x.csv", o), CsvError);
  std::istringstream empty("");
  EXPECT_THROW(bbw::csv::read_stream(empty, "e.csv", o), CsvError);
}

TEST(Csv, MissingColumnNamesIt) {
  std::istringstream in("a,c\n1,2\n");
  ReadOptions o;
  o.required = {"a", "b"};
  try {
    bbw::csv::read_stream(in, "m.csv", o);
    FAIL();
  } catch (const CsvError& e) {
    EXPECT_NE(std::string(e.what()).find("required column 'b' is missing"), std::string::npos);
  }
}

TEST(Csv, RefusesHugeFile) {
  ReadOptions o;
  o.required = {"a"};
  o.max_bytes = 2;
  const std::string path = ::testing::TempDir() + "/huge.csv";
  {
    bbw::csv::Writer w(path, {"a"});
    w.row({1.0});
    w.close();
  }
  EXPECT_THROW(bbw::csv::read(path, o), CsvError);
  o.max_bytes = 1 << 20;
  EXPECT_EQ(bbw::csv::read(path, o).rows(), 1u);
}
