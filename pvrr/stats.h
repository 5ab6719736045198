// Per-frame stage timings, reported in the stats JSON as {"name", "ms", "ran", "reason"}.
// Stage names later issues rely on: vertex-rays, refraction, viewpoint-fit, first-pass, second-pass.
#pragma once
#include <string>
#include <vector>

namespace pvrr {

struct StageTiming {
  std::string name;
  double ms = 0;
  bool ran = false;
  std::string reason;  // why it was skipped (empty when it ran)
};

struct FrameStages {
  std::vector<StageTiming> stages;
  void ran(const std::string& name, double ms) { stages.push_back({name, ms, true, ""}); }
  void skipped(const std::string& name, const std::string& reason) { stages.push_back({name, 0, false, reason}); }
};

}  // namespace pvrr
