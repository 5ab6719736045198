// Environment meshes whose file carries materials (MeshData::parts, glTF primitives): buildScene makes one
// environment mesh per part, holding only the part's vertices, with the part's base colour and texture, and
// refuses parts that do not cover the triangles in order.
#include <gtest/gtest.h>

#include <string>

#include "pvrr/base/error.h"
#include "pvrr/scene/animation.h"
#include "pvrr/scene/scene_build.h"

namespace pvrr {
namespace {

// Two triangles sharing no vertex, 6 vertices; part 0 red and textured, part 1 blue.
MeshData twoParts() {
  MeshData m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {3, 0, 0}, {2, 1, 0}};
  m.uvs = {{0, 0}, {1, 0}, {0, 1}, {0.5, 0.5}, {0.5, 0.5}, {0.5, 0.5}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  MeshPart a;
  a.name = "primitive0";
  a.first_triangle = 0;
  a.triangle_count = 1;
  a.base_color = Vec3(1, 0, 0);
  a.texture = Texture{"", 2, 1, {255, 255, 255, 0, 0, 0}};
  MeshPart b;
  b.name = "primitive1";
  b.first_triangle = 1;
  b.triangle_count = 1;
  b.base_color = Vec3(0, 0, 1);
  m.parts = {a, b};
  return m;
}

SceneDesc oneMeshScene() {
  SceneDesc d;
  d.source = "x.json";
  EnvObjectDesc o;
  o.type = EnvObjectDesc::Type::Mesh;
  o.name = "car";
  o.file = "car.glb";
  o.position = Vec3(10, 0, 0);
  // The object's own material: not used for the parts (the file's materials replace it).
  o.material.color = Vec3(0.5);
  o.material.texture = TextureDesc{};
  d.environment.push_back(o);
  return d;
}

TEST(MeshParts, EachPartBecomesAMeshWithTheFilesMaterial) {
  const Scene s = buildScene(oneMeshScene(), [](const std::string&) { return twoParts(); });
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].name, "car/primitive0");
  EXPECT_EQ(s.meshes[1].name, "car/primitive1");
  for (const EnvMesh& m : s.meshes) {
    EXPECT_EQ(m.positions.size(), 3u);  // only the part's own vertices
    ASSERT_EQ(m.triangles.size(), 1u);
    EXPECT_EQ(m.anchor, Vec3(10, 0, 0));
  }
  EXPECT_EQ(Vec3(s.meshes[1].positions[1]), Vec3(3, 0, 0));
  EXPECT_EQ(glm::vec2(s.meshes[0].uvs[2]), glm::vec2(0, 1));
  const DiffuseMaterial& red = s.materials[size_t(s.meshes[0].material)];
  const DiffuseMaterial& blue = s.materials[size_t(s.meshes[1].material)];
  EXPECT_EQ(red.color, Vec3(1, 0, 0));
  EXPECT_EQ(blue.color, Vec3(0, 0, 1));
  EXPECT_EQ(blue.texture, -1);
  ASSERT_EQ(s.textures.size(), 1u);  // the part's; the object's checker was not made
  ASSERT_EQ(red.texture, 0);
  EXPECT_EQ(s.textures[0].width, 2);
  EXPECT_EQ(s.textures[0].rgb[3], 0);
}

// An animated object with parts becomes several meshes: every part moves with it, and an animated object
// after it moves its own mesh (the meshes are matched to the file's objects, not by position in the list).
TEST(MeshParts, AnimatedPartsAndTheObjectsAfterThemMove) {
  SceneDesc d = oneMeshScene();
  AnimationDesc slide;
  slide.keys = {Keyframe{0, Vec3(0), Vec3(0)}, Keyframe{1, Vec3(0, 0, -4), Vec3(0)}};
  d.environment[0].animation = slide;
  EnvObjectDesc box;
  box.type = EnvObjectDesc::Type::Box;
  box.name = "box";
  box.position = Vec3(0, 5, 0);
  box.size = Vec3(1);
  AnimationDesc lift;
  lift.keys = {Keyframe{0, Vec3(0), Vec3(0)}, Keyframe{1, Vec3(0, 2, 0), Vec3(0)}};
  box.animation = lift;
  d.environment.push_back(box);
  Scene s = buildScene(d, [](const std::string&) { return twoParts(); });
  ASSERT_EQ(s.meshes.size(), 3u);
  const auto centre = [](const EnvMesh& m) {
    Vec3 sum(0);
    for (const glm::vec3& p : m.positions) sum += m.anchor + Vec3(p);
    return sum / double(m.positions.size());
  };
  const Vec3 part0 = centre(s.meshes[0]), part1 = centre(s.meshes[1]), cube = centre(s.meshes[2]);
  EXPECT_TRUE(applyAnimation(s, d, 0.5));
  EXPECT_NEAR(glm::length(centre(s.meshes[0]) - (part0 + Vec3(0, 0, -2))), 0.0, 1e-5);
  EXPECT_NEAR(glm::length(centre(s.meshes[1]) - (part1 + Vec3(0, 0, -2))), 0.0, 1e-5);
  EXPECT_NEAR(glm::length(centre(s.meshes[2]) - (cube + Vec3(0, 1, 0))), 0.0, 1e-5);
}

TEST(MeshParts, PartsThatDoNotCoverTheTrianglesAreRefused) {
  const auto refusal = [](MeshData m) {
    try {
      (void)buildScene(oneMeshScene(), [&](const std::string&) { return m; });
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  MeshData gap = twoParts();
  gap.parts[1].first_triangle = 0;
  EXPECT_EQ(refusal(gap), "x.json: environment[0] (car): car.glb: part 1 (primitive1): its triangles do not follow the "
                          "previous part's");
  MeshData missing = twoParts();
  missing.parts.pop_back();
  EXPECT_EQ(refusal(missing), "x.json: environment[0] (car): car.glb: the material parts miss triangles");
  MeshData nan_colour = twoParts();
  nan_colour.parts[0].base_color.g = std::nan("");
  EXPECT_NE(refusal(nan_colour).find("part 0 (primitive0): the base colour is not a finite colour >= 0"), std::string::npos);
  MeshData short_texture = twoParts();
  short_texture.parts[0].texture->rgb.pop_back();
  EXPECT_NE(refusal(short_texture).find("the base colour texture's pixels do not match its size"), std::string::npos);
}

}  // namespace
}  // namespace pvrr
