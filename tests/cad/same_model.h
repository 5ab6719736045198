// Test helper: two CAD files hold the same model, compared as numbers (see expectSameModel).
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "cad/cad_import.h"

namespace pvrr::cad {

// "The shipped file is current": the regenerated file holds the same model as the shipped one. Compared as
// numbers, not bytes: the fit's last bits (and so the printed digits) follow the machine's libm and vector
// units, e.g. 5.99453957E-09 on one x86-64 and 5.994539605E-09 on another. Knots, weights and trim points to
// 1e-9 relative, control points to 1e-9 of the model size; any real change of the design is far larger.
inline void expectSameModel(const std::string& regenerated, const std::string& shipped) {
  const ImportedModel a = importCadFile(regenerated), b = importCadFile(shipped);
  ASSERT_EQ(a.faces.size(), b.faces.size()) << shipped << " is out of date";
  EXPECT_EQ(a.unit_name, b.unit_name) << shipped << " is out of date";
  constexpr double kRel = 1e-9;
  for (std::size_t f = 0; f < a.faces.size(); ++f) {
    const NurbsDefinition& da = a.faces[f].surface->definition();
    const NurbsDefinition& db = b.faces[f].surface->definition();
    ASSERT_EQ(da.degree_u, db.degree_u) << shipped << " is out of date";
    ASSERT_EQ(da.degree_v, db.degree_v) << shipped << " is out of date";
    ASSERT_EQ(da.points.size(), db.points.size()) << shipped << " is out of date";
    ASSERT_EQ(da.knots_u.size(), db.knots_u.size()) << shipped << " is out of date";
    ASSERT_EQ(da.knots_v.size(), db.knots_v.size()) << shipped << " is out of date";
    ASSERT_EQ(da.weights.size(), db.weights.size()) << shipped << " is out of date";
    double size = 0;
    for (const Vec3& q : db.points) size = std::max(size, glm::length(q));
    for (std::size_t i = 0; i < da.points.size(); ++i)
      EXPECT_LT(glm::length(da.points[i] - db.points[i]), kRel * size) << shipped << ": pole " << i << " differs";
    for (std::size_t i = 0; i < da.knots_u.size(); ++i) EXPECT_NEAR(da.knots_u[i], db.knots_u[i], kRel * size);
    for (std::size_t i = 0; i < da.knots_v.size(); ++i) EXPECT_NEAR(da.knots_v[i], db.knots_v[i], kRel * size);
    for (std::size_t i = 0; i < da.weights.size(); ++i) EXPECT_NEAR(da.weights[i], db.weights[i], kRel);
    ASSERT_EQ(a.faces[f].trim.has_value(), b.faces[f].trim.has_value()) << shipped << " is out of date";
    if (!a.faces[f].trim) continue;
    const std::vector<Vec2> la = a.faces[f].trim->loop(), lb = b.faces[f].trim->loop();
    ASSERT_EQ(la.size(), lb.size()) << shipped << " is out of date";
    for (std::size_t i = 0; i < la.size(); ++i)
      EXPECT_LT(glm::length(la[i] - lb[i]), kRel * size) << shipped << ": trim point " << i << " differs";
  }
}

}  // namespace pvrr::cad
