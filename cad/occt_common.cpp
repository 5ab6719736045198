// OpenCASCADE helpers shared by the STEP/IGES reader and writer (see occt_common.h).
#include "cad/occt_common.h"

#include <IGESControl_Controller.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>

#include <algorithm>

namespace pvrr::cad::occt {

std::mutex& translationMutex() {
  static std::mutex m;
  return m;
}

void silence() {
  static std::once_flag once;
  std::call_once(once, [] {
    Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
    IGESControl_Controller::Init();
  });
}

std::string failureMessage(const Standard_Failure& f) {
  const char* m = f.GetMessageString();
  std::string type = f.DynamicType()->Name();
  return (m && *m) ? type + ": " + m : type;
}

double poleSize(const Handle(Geom_BSplineSurface)& bs) {
  Vec3 lo(kInf), hi(-kInf);
  for (int i = 1; i <= bs->NbUPoles(); ++i)
    for (int j = 1; j <= bs->NbVPoles(); ++j) {
      const Vec3 p = toVec(bs->Pole(i, j));
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  return std::max(glm::length(hi - lo), 1e-300);
}

}  // namespace pvrr::cad::occt
