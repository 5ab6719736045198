// Error-against-run-time plots of a sweep (pvrr sweep, pvrr plot).
#pragma once
#include <string>
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

// Writes DIR/error_vs_time.png and .svg (median error, log axis, against frame time; one series per mode;
// points labelled by tessellation and map size; the reference's frame time marked) and
// DIR/error_vs_vertices.png (median and p95 against vertex count, log-log). PNGs are VTK charts rendered
// in a headless EGL context of our own; the SVG is written directly.
void writeSweepPlots(const std::string& dir, const std::vector<SweepRow>& rows);

}  // namespace pvrr::app
