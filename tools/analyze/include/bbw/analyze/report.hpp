// Writes DIR/analysis.json, DIR/report.md and the PNG plots of one analysis.
#pragma once

#include <string>

#include "bbw/analysis/analysis.hpp"
#include "bbw/analyze/cli.hpp"

namespace bbw::analyze {

std::string analysis_json(const LoadedRecording& in, const analysis::AnalysisOptions& o,
                          const analysis::AnalysisResult& r);

// Creates DIR, writes analysis.json, plot_data.csv, the gnuplot scripts, PNGs and report.md.
// With plots=false no gnuplot is run (report.md then says so). Throws on a write failure.
void write_outputs(const std::string& dir, const LoadedRecording& in, const analysis::AnalysisOptions& o,
                   const analysis::AnalysisResult& r, bool plots = true);

}  // namespace bbw::analyze
