// pvrr fov from the command line (issue 21): its files, the JSON's zones and footprints for the default car
// mirror against R46 Class III, and one-line errors that leave no output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "app/run_pvrr.h"

namespace {

namespace fs = std::filesystem;
using pvrr::test::CliResult;
using pvrr::test::expectOneLineError;
using pvrr::test::runPvrr;
using pvrr::test::slurp;


TEST(FovCli, CarMirrorAgainstR46ClassIII) {
  const fs::path dir = pvrr::test::freshTestDir("fov-ok");
  const CliResult r = runPvrr("fov models/car-mirror.json --samples 61 --out '" + (dir / "out").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"fov.json", "fov.png", "fov.svg", "magnification.png", "magnification.svg"})
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "out" / "fov.json"));
  EXPECT_EQ(j["element"], "door-mirror");
  EXPECT_EQ(j["eyes"], (nlohmann::json{"left", "right"}));
  EXPECT_EQ(j["ocular_points"]["from"], "vehicle.ocular_points");
  EXPECT_NEAR(j["ocular_points"]["left"][1].get<double>(), 0.0325, 1e-12);  // vehicle frame: y to the left
  for (const char* eye : {"left", "right"}) {
    EXPECT_GT(j["footprint"][eye]["polygon"].size(), 100u);
    EXPECT_GT(j["footprint"][eye]["road"].get<int>(), 0);
  }
  ASSERT_GE(j["footprint"]["union"]["polygons"].size(), 1u);
  EXPECT_GT(j["footprint"]["union"]["polygons"][0].size(), 100u);
  ASSERT_EQ(j["zones"].size(), 2u);  // the scene's default regulation: r46-class-iii, two zones
  for (const auto& z : j["zones"]) {
    EXPECT_EQ(z["regulation"], "r46-class-iii");
    EXPECT_GE(z["covered_fraction"].get<double>(), 0);
    EXPECT_LE(z["covered_fraction"].get<double>(), 1);
    EXPECT_FALSE(z["verified"].get<bool>());  // R46's zone numbers are not confirmed in the primary text yet
  }
  EXPECT_NE(r.out.find("r46-class-iii / "), std::string::npos) << r.out;
  // The convex mirror: radii of about 1.3 m, magnification below 1.
  const auto& s = j["surface"];
  EXPECT_GT(s["mean_radius_m"].get<double>(), 1.0);
  EXPECT_LT(s["mean_radius_m"].get<double>(), 2.0);
  EXPECT_LE(s["principal_radius_min_m"].get<double>(), s["principal_radius_max_m"].get<double>());
  EXPECT_GT(s["magnification_min"].get<double>(), 0);
  EXPECT_LT(s["magnification_max"].get<double>(), 1);
  // R46 Annex 7's three-point radius is what the minimum-radius requirement is checked against.
  const double annex7_r = s["annex7"]["r_m"].get<double>();
  EXPECT_GT(annex7_r, 1.2);
  EXPECT_LT(annex7_r, 1.6);
  ASSERT_EQ(s["annex7"]["points"].size(), 3u);
  const auto& req = j["regulations"][0]["mirror_requirements"][0];
  EXPECT_EQ(req["name"], "min_mean_radius_m");
  EXPECT_DOUBLE_EQ(req["measured"].get<double>(), annex7_r);
  EXPECT_TRUE(req["pass"].get<bool>());
  fs::remove_all(dir);
}

// The car mirror turned 6 deg about the vertical fails R46 Class III's near strip; --aim turns it back to pass,
// and the scene it writes loads, builds and passes on its own.
TEST(FovCli, AimTurnsAMisAimedMirrorToPass) {
  const fs::path dir = pvrr::test::freshTestDir("fov-aim");
  const CliResult r = runPvrr(
      "fov models/car-mirror.json --set 'elements[0].pose.normal=[0.47697, 0.1238, 0.87021]' --aim --aim-range 8 "
      "--samples 41 --out '" +
      (dir / "out").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"fov.json", "aimed.json", "aimed/fov.png", "aimed/fov.svg"})
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "out" / "fov.json"));
  EXPECT_FALSE(j["pass"].get<bool>());
  const auto& aim = j["aim"];
  EXPECT_FALSE(aim["pass_before"].get<bool>());
  EXPECT_TRUE(aim["pass"].get<bool>()) << aim.dump(2);
  EXPECT_DOUBLE_EQ(aim["shortfall"].get<double>(), 0);
  EXPECT_LT(aim["yaw_deg"].get<double>(), -3);  // turned back towards the car's own adjustment
  ASSERT_EQ(aim["zones"].size(), 2u);
  for (const auto& z : aim["zones"]) EXPECT_TRUE(z["pass"].get<bool>());
  EXPECT_NE(r.out.find("aim: yaw "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("every zone passes"), std::string::npos) << r.out;
  // The aimed scene on its own: the same verdict and coverage at the same sampling.
  const CliResult again = runPvrr("fov '" + (dir / "out" / "aimed.json").string() + "' --samples 41 --out '" +
                                  (dir / "again").string() + "'");
  ASSERT_EQ(again.code, 0) << again.err;
  const nlohmann::json k = nlohmann::json::parse(slurp(dir / "again" / "fov.json"));
  EXPECT_TRUE(k["pass"].get<bool>());
  for (size_t i = 0; i < 2; ++i)
    EXPECT_DOUBLE_EQ(k["zones"][i]["covered_fraction"].get<double>(),
                     aim["zones"][i]["covered_fraction"].get<double>());
  fs::remove_all(dir);
}

TEST(FovCli, OneEyeAndAnExplicitRegulation) {
  const fs::path dir = pvrr::test::freshTestDir("fov-left");
  const CliResult r = runPvrr(
      "fov models/car-mirror.json --samples 31 --eyes left --regulation fmvss111-driver --out '" + dir.string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "fov.json"));
  EXPECT_EQ(j["eyes"], (nlohmann::json{"left"}));
  EXPECT_FALSE(j["footprint"].contains("right"));
  ASSERT_EQ(j["zones"].size(), 1u);
  EXPECT_EQ(j["zones"][0]["regulation"], "fmvss111-driver");
  // FMVSS 111 asks for a plane (unit magnification) mirror: the convex car mirror fails it.
  EXPECT_EQ(j["regulations"][0]["mirror_requirements"][0]["name"], "unit_magnification");
  EXPECT_FALSE(j["regulations"][0]["mirror_requirements"][0]["pass"].get<bool>());
  EXPECT_FALSE(j["pass"].get<bool>());
  fs::remove_all(dir);
}


TEST(FovCli, ErrorsAreOneLineAndLeaveNothing) {
  const fs::path dir = pvrr::test::freshTestDir("fov-err");
  const std::string out = (dir / "out").string();
  expectOneLineError(runPvrr("fov models/plane-mirror.json --out '" + out + "'"),
                     "models/plane-mirror.json: vehicle: missing");
  expectOneLineError(runPvrr("fov models/car-mirror.json --regulation r46-class-ix --out '" + out + "'"),
                     "unknown regulation \"r46-class-ix\" (known: fmvss111-driver, r46-class-ii");
  expectOneLineError(runPvrr("fov models/car-mirror.json --set 'vehicle.forward=[0,1,0]' --out '" + out + "'"),
                     "vehicle.forward: expected a direction perpendicular to vehicle.up");
  // Turned to face the sky: every ray leaves above the horizon.
  expectOneLineError(
      runPvrr("fov models/car-mirror.json --set 'elements[0].pose.normal=[0.3, 0.6, 0.74]' --out '" + out + "'"),
      "models/car-mirror.json: elements[0] (door-mirror): the mirror sees no road");
  expectOneLineError(runPvrr("fov models/car-mirror.json --element mirror --out '" + out + "'"),
                     "no element named \"mirror\"");
  expectOneLineError(runPvrr("fov models/car-mirror.json --aim --aim-range 90 --out '" + out + "'"),
                     "pvrr fov: --aim-range: expected degrees in [1, 45]");
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

}  // namespace
