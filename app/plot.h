// Error-against-run-time plots of a sweep (pvrr sweep, pvrr plot).
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace pvrr::app {

struct SweepRow {
  std::string mode;
  int tessellation = 0, map_size = 0;
  std::string vary;  // "PATH=V;..." of the --vary values, or ""
  long vertices = 0;
  double frame_ms = 0, reference_ms = 0;
  double median_arcmin = 0, p95_arcmin = 0, max_arcmin = 0, psnr_db = 0;
};

// The CSV of a sweep: header + rows (full precision). Parsing throws pvrr::Error naming the file and line.
std::string sweepCsv(const std::vector<SweepRow>& rows);
std::vector<SweepRow> readSweepCsv(const std::string& path);

// One series of a plot. In the error-against-time chart: one (mode, map size, --vary) group of the CSV, its
// points in CSV order, each labelled "tessellation/map size".
struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
  std::vector<std::string> labels;  // per point ("" or empty vector: none)
  bool line = false;
  bool dashed = false;  // lines only
  int colour = 0;  // index into the palette (6 colours)
  int marker = 0;  // index into the markers (circle, square, diamond, cross, plus): with the colour, unique
};

// The series of error_vs_time.png/.svg: every (mode, map size, vary) group present in `rows` gets exactly
// one series, in the order the groups first appear, with a distinct (colour, marker) pair. Errors are
// clamped to >= 1e-6 arcmin for the log axis.
std::vector<PlotSeries> errorVsTimeSeries(const std::vector<SweepRow>& rows);

// An axis range that holds every value strictly inside, away from the borders (points on the border are
// half clipped, and one in a corner hides under the legend): linear axes pad by 8 % of the span on each side
// (or by 10 % of the value when all are equal), starting at 0 instead of below it when the lowest value
// stays at least a quarter of that padding away; log axes pad by a factor of 1.6 on each side. Non-finite values (and non-positive ones on a log
// axis) are ignored. Throws pvrr::Error when no value is left.
std::pair<double, double> paddedRange(const std::vector<double>& values, bool log);

// Writes DIR/error_vs_time.png and .svg (median error, log axis, against frame time; one series per mode;
// points labelled by tessellation and map size; the reference's frame time marked) and
// DIR/error_vs_vertices.png (median and p95 against vertex count, log-log). PNGs are VTK charts rendered
// in a headless EGL context of our own; the SVG is written directly.
void writeSweepPlots(const std::string& dir, const std::vector<SweepRow>& rows);

}  // namespace pvrr::app
