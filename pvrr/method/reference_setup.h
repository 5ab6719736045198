// The reference tracer as every caller sets it up (pvrr render --mode raytrace, pvrr compare's reference, the
// viewer's live reference in app/view/reference_tiles.h): the scene's depth and dispersion, and the caustic
// light of the lights with caustics on (referenceCaustics, docs/caustics.md "In the reference picture"), so
// that one view gives one reference picture whoever traces it.
#pragma once
#include <optional>

#include "pvrr/base/frame.h"
#include "pvrr/method/caustic_mesh.h"
#include "pvrr/trace/tracer.h"

namespace pvrr {

class ReferenceSetup {
 public:
  // Computes the caustic light once (seconds on a lens in sunlight; nothing without a caustic light).
  explicit ReferenceSetup(const RayScene& rays);
  // The options point into this object's caustic light: keep it alive while a tracer made with them runs.
  ReferenceSetup(const ReferenceSetup&) = delete;
  ReferenceSetup& operator=(const ReferenceSetup&) = delete;

  const TraceOptions& options() const { return options_; }
  bool hasCaustics() const { return caustics_.has_value(); }
  // The stage kReferenceCausticsStage: ran (photons, receivers) or skipped with the reason.
  const FrameStages& stages() const { return stages_; }

 private:
  FrameStages stages_;
  std::optional<CausticLightField> caustics_;
  TraceOptions options_;
};

}  // namespace pvrr
