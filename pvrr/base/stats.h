// Per-frame stage timings, reported in the stats JSON as {"name", "ms", "ran", "reason"} (plus "count" and
// "note" where a stage sets them).
// Stage names later issues rely on: vertex-rays, refraction, viewpoint-fit, first-pass, second-pass,
// colour-channels (count: the most channels of an element), nested-passes (count: first passes of
// elements seen inside other elements' maps; impostor mode: (cube, element) pairs, each element drawn into
// another element's cubes: the mirrors, and the scene's lens if it has only one).
#pragma once
#include <string>
#include <vector>

namespace pvrr {

struct StageTiming {
  std::string name;
  double ms = 0;
  bool ran = false;
  std::string reason;  // why it was skipped (empty when it ran)
  int count = -1;      // how many of the stage's units ran (channels, passes); -1: not counted
  std::string note;    // what it did, when it ran (e.g. "16 spectral samples in 6 additive draws")
};

struct FrameStages {
  std::vector<StageTiming> stages;
  void ran(const std::string& name, double ms, int count = -1, const std::string& note = "") {
    stages.push_back({name, ms, true, "", count, note});
  }
  void skipped(const std::string& name, const std::string& reason) { stages.push_back({name, 0, false, reason, -1, ""}); }
  const StageTiming* find(const std::string& name) const {
    for (const StageTiming& s : stages)
      if (s.name == name) return &s;
    return nullptr;
  }
};

}  // namespace pvrr
