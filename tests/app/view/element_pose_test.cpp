// app/view/element_pose.*: turning an element about its vertex, and the overrides that hold the turned pose.
#include "app/view/element_pose.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace pvrr::app::view {
namespace {

// Exact up to double rounding of two rotations.
constexpr double kPoseTol = 1e-12;

void expectNear(const Vec3& a, const Vec3& b) {
  EXPECT_NEAR(glm::length(a - b), 0, kPoseTol) << a.x << " " << a.y << " " << a.z;
}

TEST(ViewElementPose, YawTurnsTheNormalTowardsLocalXAndPitchTowardsUp) {
  const Vec3 n(0, 0, 1), up(0, 1, 0);  // local +x = up x normal = (1, 0, 0)
  TurnedPose p = turnElementPose(n, up, radians(90), 0);
  expectNear(p.normal, Vec3(1, 0, 0));
  expectNear(p.up, up);
  p = turnElementPose(n, up, 0, radians(90));
  expectNear(p.normal, Vec3(0, 1, 0));
  expectNear(p.up, Vec3(0, 0, -1));
  // Yaw first, then pitch about the turned local x: the normal's elevation is the pitch, its azimuth the yaw.
  const double yaw = radians(30), pitch = radians(20);
  p = turnElementPose(n, up, yaw, pitch);
  expectNear(p.normal, Vec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)));
  EXPECT_NEAR(glm::dot(p.normal, p.up), 0, kPoseTol);
}

TEST(ViewElementPose, TurnsAreAboutTheElementsOwnFrame) {
  // A mirror facing +x with a tilted up hint: the turn keeps the normal's angle to the orthogonalised up.
  const Vec3 n = glm::normalize(Vec3(1, 0.2, 0)), hint(0.1, 1, 0.3);
  const TurnedPose p = turnElementPose(n, hint, radians(12), 0);
  const Vec3 y = glm::normalize(hint - glm::dot(hint, n) * n);
  EXPECT_NEAR(glm::dot(p.normal, y), 0, kPoseTol);                       // yaw stays in the plane normal to y
  EXPECT_NEAR(std::acos(glm::dot(p.normal, n)), radians(12), kPoseTol);  // by the angle asked
  EXPECT_GT(glm::dot(p.normal, glm::cross(y, n)), 0);                    // towards local +x
}

TEST(ViewElementPose, MovesInTheElementsFrameAndWritesTheFilesUnit) {
  const Vec3 n(0, 0, 1), up(0, 1, 0), p(1, 2, 3);  // local x = (1, 0, 0)
  expectNear(movedElementPosition(p, n, up, Vec3(0.01, -0.02, 0.03)), Vec3(1.01, 1.98, 3.03));
  // A millimetre scene: the override is in millimetres, exactly the moved metres / 0.001.
  const Vec3 moved = movedElementPosition(p, glm::normalize(Vec3(1, 0, 1)), up, Vec3(0, 0, 0.002));
  const std::string o = positionOverride(3, moved, 0.001);
  ASSERT_EQ(o.rfind("elements[3].pose.position=", 0), 0u);
  const nlohmann::json j = nlohmann::json::parse(o.substr(o.find('=') + 1));
  EXPECT_EQ(j[0].get<double>(), moved.x / 0.001);
  EXPECT_EQ(j[2].get<double>(), moved.z / 0.001);
  EXPECT_NEAR(glm::length(moved - p), 0.002, kPoseTol);
}

TEST(ViewElementPose, OverridesHoldThePoseExactly) {
  const TurnedPose p = turnElementPose(Vec3(0.3834, 0.1238, 0.9153), Vec3(0, 1, 0), radians(3), radians(-2));
  const std::vector<std::string> o = poseOverrides(2, p);
  ASSERT_EQ(o.size(), 2u);
  ASSERT_EQ(o[0].rfind("elements[2].pose.normal=", 0), 0u);
  ASSERT_EQ(o[1].rfind("elements[2].pose.up=", 0), 0u);
  const auto parse = [](const std::string& s) {
    const nlohmann::json j = nlohmann::json::parse(s.substr(s.find('=') + 1));
    return Vec3(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
  };
  EXPECT_EQ(parse(o[0]), p.normal);  // bit for bit: the saved view holds the pose the window showed
  EXPECT_EQ(parse(o[1]), p.up);
}

}  // namespace
}  // namespace pvrr::app::view
