#include "pvrr/scene/scene_build.h"

#include <algorithm>
#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>

#include "cad/cad_import.h"
#include "pvrr/base/error.h"
#include "cad/sag.h"
#include "pvrr/base/image.h"
#include "pvrr/optics/material.h"
#include "pvrr/scene/texture_gen.h"

namespace pvrr {

namespace {

// A surface scaled by a constant (file units -> metres), derivatives included.
class ScaledSurface : public cad::Surface {
 public:
  ScaledSurface(cad::SurfacePtr base, double factor) : base_(std::move(base)), f_(factor) {}
  cad::ParamDomain domain() const override { return base_->domain(); }
  cad::SurfaceDerivs evaluate(double u, double v) const override {
    cad::SurfaceDerivs d = base_->evaluate(u, v);
    d.p *= f_;
    d.du *= f_;
    d.dv *= f_;
    d.duu *= f_;
    d.duv *= f_;
    d.dvv *= f_;
    return d;
  }
  Vec3 normal(double u, double v) const override { return base_->normal(u, v); }
  std::string describe() const override { return base_->describe() + " x " + std::to_string(f_); }

 private:
  cad::SurfacePtr base_;
  double f_;
};

cad::Outline toOutline(const OutlineDesc& o) {
  switch (o.shape) {
    case OutlineDesc::Shape::Rectangle: return cad::Outline::rectangle(o.width_m, o.height_m, o.corner_radius_m);
    case OutlineDesc::Shape::Ellipse: return cad::Outline::ellipse(o.width_m, o.height_m);
    case OutlineDesc::Shape::Circle: return cad::Outline::circle(o.width_m);
  }
  return cad::Outline::circle(o.width_m);
}

cad::SagSurfacePtr makeSag(const SurfaceDesc& s, const cad::Outline& outline, double z_vertex) {
  switch (s.type) {
    case SurfaceDesc::Type::Plane: return cad::makePlane(outline, z_vertex);
    case SurfaceDesc::Type::Sphere: return cad::makeSphere(s.radius_m, outline, z_vertex);
    case SurfaceDesc::Type::Asphere: return cad::makeAsphere(s.radius_m, s.conic, s.coefficients, outline, z_vertex);
    case SurfaceDesc::Type::Toric:
      return cad::makeToric(s.radius_a_m, s.radius_b_m, radians(s.axis_deg), outline, z_vertex);
    case SurfaceDesc::Type::Cylinder: return cad::makeCylinder(s.radius_m, radians(s.axis_deg), outline, z_vertex);
    default: break;
  }
  throw InternalError("makeSag: not a sag surface");
}

// A lens surface in the lens frame: analytic, or a face of a STEP/IGES file as a NURBS graph over the lens
// plane (cad::makeNurbsSag), in the file's unit converted to metres and translated along z only, so that
// its point over the lens axis is the vertex. The face's trim loop, when it has one, must contain the lens
// outline (within the loop's own chord error). `where` ("<scene>: elements[i].back") starts every message.
cad::SagSurfacePtr makeLensSurface(const SurfaceDesc& s, const cad::Outline& outline, const std::string& where) {
  if (s.isSag()) return makeSag(s, outline, 0.0);
  if (s.type != SurfaceDesc::Type::Cad) throw InternalError("makeLensSurface: not a lens surface type");
  cad::ImportedModel model;
  try {
    model = cad::importCadFile(s.file);
  } catch (const Error& err) {
    throw Error(where + ".file: " + err.what());
  }
  if (s.face < 0 || size_t(s.face) >= model.faces.size())
    throw Error(where + ".face: " + s.file + ": face " + std::to_string(s.face) + " requested, the file has " +
                std::to_string(model.faces.size()) + " face(s) (indices from 0)");
  const cad::ImportedFace& face = model.faces[size_t(s.face)];
  auto surface = std::make_shared<cad::NurbsSurface>(cad::scaled(*face.surface, model.unit_to_metres));
  double trim_tol = 0;
  if (face.trim)
    trim_tol = 1.01 * face.trim_chord_error_uv + 1e-9 * std::max(face.trim->width(), face.trim->height());
  try {
    return cad::makeNurbsSag(std::move(surface), outline, face.trim, trim_tol,
                             s.file + " face " + std::to_string(s.face));
  } catch (const Error& err) {
    throw Error(where + ": " + err.what());
  }
}

// Local frame -> world: z = normal, y = up orthogonalised, x = y x z.
Mat4 poseMatrix(const PoseDesc& p) {
  const Vec3 z = glm::normalize(p.normal);
  const Vec3 y = glm::normalize(p.up - glm::dot(p.up, z) * z);
  const Vec3 x = glm::cross(y, z);
  Mat4 m(1.0);
  m[0] = Vec4(x, 0);
  m[1] = Vec4(y, 0);
  m[2] = Vec4(z, 0);
  m[3] = Vec4(p.position, 1);
  return m;
}

Mat4 observerToWorld(const Observer& ob) { return glm::inverse(ob.view()); }

Texture makeTexture(const TextureDesc& t, const std::string& name) {
  Texture out;
  out.name = name;
  if (t.kind == TextureDesc::Kind::Image) {
    ImageRGB8 img = readPng(t.image_path);
    out.width = img.width;
    out.height = img.height;
    out.rgb = std::move(img.rgb);
  } else {
    TextureImage img = generateTexture(t);
    out.width = img.width;
    out.height = img.height;
    out.rgb = std::move(img.rgb);
  }
  return out;
}

// Grid size for an adaptive tessellation request: cells whose sagitta h^2 k / 8 stays below the chordal
// tolerance at the surface's centre curvature.
int gridForTolerance(const cad::Surface& s, const cad::Outline* outline, double tol_m) {
  const cad::ParamDomain d = s.domain();
  const double cu = 0.5 * (d.u0 + d.u1), cv = 0.5 * (d.v0 + d.v1);
  const cad::Curvature k = s.curvature(cu, cv);
  const double kmax = std::max({std::abs(k.k1), std::abs(k.k2), 1e-9});
  const cad::SurfaceDerivs sd = s.evaluate(cu, cv);
  const double extent = outline ? std::max(outline->width(), outline->height())
                                : std::max(glm::length(sd.du) * (d.u1 - d.u0), glm::length(sd.dv) * (d.v1 - d.v0));
  const double h = std::sqrt(8.0 * tol_m / kmax);
  return std::clamp(int(std::ceil(extent / h)) + 1, 3, 257);
}

}  // namespace

double defaultBaseCurve(double sphere_d) {
  // Vogel's rule, the usual choice of front (object-side) curve for a given sphere power.
  return sphere_d >= 0 ? sphere_d + 6.0 : sphere_d / 2.0 + 6.0;
}

PrescriptionRadii prescriptionRadii(double sphere_d, double cylinder_d, double base_curve_d, double n, double t_m) {
  // Light enters the object-side surface (power F1, the lens's back in our naming) and leaves through the
  // eye-side surface (F2). Back vertex power: F_v = F1 / (1 - (t/n) F1) + F2. Surface powers in our sign
  // convention (cad/sag.h): F1 = -(n - 1) / R_back, F2 = (n - 1) / R_front.
  const double f1 = base_curve_d;
  const double f1_eff = f1 / (1.0 - (t_m / n) * f1);
  auto frontRadius = [&](double power) {
    const double f2 = power - f1_eff;
    return std::abs(f2) < 1e-12 ? kInf : (n - 1.0) / f2;
  };
  PrescriptionRadii r;
  r.back_radius_m = std::abs(f1) < 1e-12 ? kInf : -(n - 1.0) / f1;
  r.front_radius_a_m = frontRadius(sphere_d);
  r.front_radius_b_m = frontRadius(sphere_d + cylinder_d);
  return r;
}

namespace {

// The material parts a loader returned cover its triangles in order, with finite colours and whole images.
void checkMeshParts(const MeshData& md, const std::string& where) {
  size_t next = 0;
  for (size_t i = 0; i < md.parts.size(); ++i) {
    const MeshPart& p = md.parts[i];
    const std::string at = where + ": part " + std::to_string(i) + " (" + p.name + "): ";
    if (p.first_triangle != next || p.triangle_count == 0 || p.triangle_count > md.triangles.size() - next)
      throw Error(at + "its triangles do not follow the previous part's");
    next += p.triangle_count;
    if (!isFinite(p.base_color) || glm::any(glm::lessThan(p.base_color, Vec3(0))))
      throw Error(at + "the base colour is not a finite colour >= 0");
    if (p.texture && (p.texture->width <= 0 || p.texture->height <= 0 ||
                      p.texture->rgb.size() != size_t(p.texture->width) * size_t(p.texture->height) * 3))
      throw Error(at + "the base colour texture's pixels do not match its size");
  }
  if (!md.parts.empty() && next != md.triangles.size()) throw Error(where + ": the material parts miss triangles");
}

// One environment mesh per material part of a loaded mesh, each holding only the vertices its triangles use,
// with the part's material (added to the scene).
// The number of ambient occluder `name` (EnvObjectDesc::occluder): in the order first met; -1 for none.
int occluderId(std::vector<std::string>& names, const std::string& name) {
  if (name.empty()) return -1;
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return int(it - names.begin());
  names.push_back(name);
  return int(names.size()) - 1;
}

void addMeshParts(Scene& scene, const EnvMesh& whole, const std::vector<MeshPart>& parts, const std::string& what,
                  size_t object, bool animated) {
  for (const MeshPart& p : parts) {
    EnvMesh sub;
    sub.name = whole.name + "/" + p.name;
    sub.anchor = whole.anchor;
    std::vector<uint32_t> remap(whole.positions.size(), UINT32_MAX);
    for (size_t t = p.first_triangle; t < p.first_triangle + p.triangle_count; ++t) {
      glm::u32vec3 tri;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = whole.triangles[t][k];
        if (remap[v] == UINT32_MAX) {
          remap[v] = uint32_t(sub.positions.size());
          sub.positions.push_back(whole.positions[v]);
          sub.normals.push_back(whole.normals[v]);
          sub.uvs.push_back(whole.uvs[v]);
        }
        tri[k] = remap[v];
      }
      sub.triangles.push_back(tri);
    }
    DiffuseMaterial mat;
    mat.color = p.base_color;
    if (p.texture) {
      mat.texture = int(scene.textures.size());
      scene.textures.push_back(*p.texture);
      scene.textures.back().name = what + ": " + p.name;
    }
    sub.material = int(scene.materials.size());
    scene.materials.push_back(mat);
    sub.occluder = whole.occluder;
    scene.mesh_object.push_back(object);
    scene.placed_meshes.push_back(animated ? sub : EnvMesh{});
    scene.mesh_motion.push_back(Mat4(1.0));
    scene.meshes.push_back(std::move(sub));
  }
}

// An environment mesh from a file (MeshLoader), posed by the object's position, rotation and scale, with
// normals from the file or, without them, from the faces. `what` names the object in messages.
// The file's material parts (MeshData::parts) are checked and moved to `parts`.
EnvMesh loadedMesh(const EnvObjectDesc& o, const MeshLoader& load_mesh, const std::string& what,
                   std::vector<MeshPart>& parts) {
  EnvMesh mesh;
  if (!load_mesh) throw Error(what + ": no mesh reader is available in this program");
  MeshData md;
  try {
    md = load_mesh(o.file);
  } catch (const Error& e) {
    throw Error(what + ": " + e.what());  // the reader names the file and the place in it
  }
  if (md.positions.empty() || md.triangles.empty()) throw Error(what + ": " + o.file + " holds no triangles");
  // The loader is a callback: what it returns is checked before anything indexes with it.
  for (size_t v = 0; v < md.positions.size(); ++v)
    if (!isFinite(md.positions[v]))
      throw Error(what + ": " + o.file + ": vertex " + std::to_string(v) + " is not finite");
  for (size_t t = 0; t < md.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (md.triangles[t][k] >= md.positions.size())
        throw Error(what + ": " + o.file + ": triangle " + std::to_string(t) + ": vertex index " +
                    std::to_string(md.triangles[t][k]) + " is out of range (the mesh has " +
                    std::to_string(md.positions.size()) + " vertices)");
  checkMeshParts(md, what + ": " + o.file);
  parts = std::move(md.parts);
  mesh.anchor = o.position;
  for (size_t v = 0; v < md.positions.size(); ++v) {
    const Vec3 p = o.rotation * (o.scale * md.positions[v]);
    mesh.positions.push_back(glm::vec3(p));
    mesh.uvs.push_back(v < md.uvs.size() ? glm::vec2(md.uvs[v]) : glm::vec2(0));
  }
  mesh.triangles = md.triangles;
  // Normals: transformed by the inverse transpose, or from the faces when the file has none.
  std::vector<Vec3> normals(md.positions.size(), Vec3(0));
  if (md.normals.size() == md.positions.size()) {
    const Mat3 nt = glm::transpose(glm::inverse(o.rotation * Mat3(glm::scale(Mat4(1.0), o.scale))));
    for (size_t v = 0; v < normals.size(); ++v) normals[v] = nt * md.normals[v];
  } else {
    for (const auto& t : mesh.triangles) {
      const Vec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
      const Vec3 fn = glm::cross(b - a, c - a);
      normals[t.x] += fn;
      normals[t.y] += fn;
      normals[t.z] += fn;
    }
  }
  for (const Vec3& n : normals) {
    const double len = glm::length(n);
    mesh.normals.push_back(glm::vec3(len > 0 ? n / len : Vec3(0, 1, 0)));
  }
  return mesh;
}

// A mirror's surface (a sag surface, a CAD face with its trim as the outline, or a subdivision surface) and
// its material.
void buildMirror(Element& el, const ElementDesc& e) {
  const SurfaceDesc& s = e.surface;
  if (s.isSag()) {
    if (!e.outline) throw Error("a " + std::string(nameOf(s.type)) + " mirror needs an outline");
    el.surface = makeSag(s, el.outline, 0.0);
  } else if (s.type == SurfaceDesc::Type::Cad) {
    cad::ImportedModel model = cad::importCadFile(s.file);
    if (s.face < 0 || size_t(s.face) >= model.faces.size())
      throw Error(s.file + ": face " + std::to_string(s.face) + " requested, the file has " +
                  std::to_string(model.faces.size()));
    const cad::ImportedFace& face = model.faces[size_t(s.face)];
    el.surface = std::make_shared<cad::NurbsSurface>(cad::scaled(*face.surface, model.unit_to_metres));
    // The trim loop (in parameter space) is the outline; an explicit outline cannot apply to (u, v).
    el.has_outline = face.trim.has_value();
    if (face.trim) el.outline = *face.trim;
  } else {
    el.surface = std::make_shared<ScaledSurface>(cad::loadSubdivisionCage(s.file), s.file_unit_m);
    el.has_outline = false;
  }
  switch (e.mirror_material.kind) {
    case MirrorMaterialDesc::Kind::Reflectance:
      el.mirror.reflectance = Vec3(e.mirror_material.reflectance);
      break;
    case MirrorMaterialDesc::Kind::Metal: {
      Metal m = lookupMetal(e.mirror_material.metal);
      el.mirror.metal = true;
      el.mirror.n = m.n_rgb();
      el.mirror.k = m.k_rgb();
      el.mirror.metal_table = std::make_shared<const Metal>(m);
      break;
    }
    case MirrorMaterialDesc::Kind::Conductor:
      el.mirror.metal = true;
      el.mirror.n = e.mirror_material.n;
      el.mirror.k = e.mirror_material.k;
      break;
  }
}

// A lens's mean thickness over its outline: the average of the thickness at the centres of a 64 x 64 grid over
// the outline's bounding box that fall inside it (the centre thickness if none does).
double meanThickness(const cad::LensSolid& lens) {
  constexpr int kSide = 64;
  const cad::Outline& o = lens.outline;
  double sum = 0;
  int count = 0;
  for (int j = 0; j < kSide; ++j)
    for (int i = 0; i < kSide; ++i) {
      const Vec2 p = o.centre() + Vec2(o.width() * ((i + 0.5) / kSide - 0.5), o.height() * ((j + 0.5) / kSide - 0.5));
      if (!o.contains(p)) continue;
      sum += lens.thicknessAt(p.x, p.y);
      ++count;
    }
  return count > 0 ? sum / count : lens.centre_thickness;
}

// A lens's glass and its two surfaces, from a prescription or given: element i of `file`, named `what` in
// messages.
void buildLens(Element& el, const ElementDesc& e, const std::string& file, size_t i, const std::string& what) {
  const LensMaterialDesc& lm = e.lens_material;
  Dispersion disp;
  switch (lm.kind) {
    case LensMaterialDesc::Kind::Named: disp = lookupLensMaterial(lm.name).dispersion; break;
    case LensMaterialDesc::Kind::Abbe: disp = Dispersion::fromAbbe(lm.n_d, lm.V_d); break;
    case LensMaterialDesc::Kind::Sellmeier: disp = Dispersion::sellmeier(lm.sellmeier_b, lm.sellmeier_c_um2); break;
  }
  if (!lm.dispersion) disp = Dispersion::constant(disp.n_d());
  el.dispersion = disp;
  el.dispersion_on = lm.dispersion;
  el.absorption_per_m = absorptionFromInternalTransmittance(lm.internal_transmittance, lm.internal_transmittance_thickness_m);
  if (!e.outline) throw Error("a lens needs an outline");
  cad::SagSurfacePtr front, back;
  double t = e.centre_thickness_m;
  if (e.prescription) {
    const PrescriptionDesc& p = *e.prescription;
    if (t <= 0) t = p.sphere_d < 0 ? 2e-3 : 1.5e-3;
    const double base = p.base_curve_d ? *p.base_curve_d : defaultBaseCurve(p.sphere_d);
    const PrescriptionRadii r = prescriptionRadii(p.sphere_d, p.cylinder_d, base, disp.n_d(), t);
    back = std::isfinite(r.back_radius_m) ? cad::makeSphere(r.back_radius_m, el.outline)
                                          : cad::makePlane(el.outline);
    if (p.cylinder_d == 0)
      front = std::isfinite(r.front_radius_a_m) ? cad::makeSphere(r.front_radius_a_m, el.outline)
                                                : cad::makePlane(el.outline);
    else
      front = cad::makeToric(r.front_radius_a_m, r.front_radius_b_m, radians(p.axis_deg), el.outline);
  } else {
    const std::string where = file + ": elements[" + std::to_string(i) + "]";
    front = makeLensSurface(e.front, el.outline, where + ".front");
    back = makeLensSurface(e.back, el.outline, where + ".back");
  }
  el.lens = cad::makeLens(front, back, el.outline, t, e.min_edge_thickness_m, what);
  if (el.absorbing()) el.shadow_path_m = meanThickness(el.lens);  // read by the shadow rule of tinted lenses only
}

}  // namespace

void animatedBounds(Scene& scene, const SceneDesc& desc);  // below, with applyAnimation

Scene buildScene(const SceneDesc& desc, const MeshLoader& load_mesh) {
  Scene scene;
  scene.source_path = desc.source;
  scene.name = std::filesystem::path(desc.source).stem().string();
  const std::string& file = desc.source;

  Observer& ob = scene.observer;
  ob.eye = desc.observer.eye;
  ob.target = desc.observer.target;
  ob.up = desc.observer.up;
  ob.fov_y_rad = radians(desc.observer.fov_y_deg);
  ob.width = desc.observer.image_width;
  ob.height = desc.observer.image_height;

  std::vector<std::string> occluders;  // EnvObjectDesc::occluder names, numbered as met
  for (size_t i = 0; i < desc.environment.size(); ++i) {
    const EnvObjectDesc& o = desc.environment[i];
    const std::string what = file + ": environment[" + std::to_string(i) + "]" + (o.name.empty() ? "" : " (" + o.name + ")");
    const double uv_scale = o.material.texture_fit ? 0.0 : o.material.texture_scale_m.x;
    EnvMesh mesh;
    std::vector<MeshPart> parts;
    switch (o.type) {
      case EnvObjectDesc::Type::Box: mesh = makeBoxMesh(o.position, o.size, o.rotation, uv_scale); break;
      case EnvObjectDesc::Type::Sphere: mesh = makeSphereMesh(o.position, o.radius_m); break;
      case EnvObjectDesc::Type::Ground:
      case EnvObjectDesc::Type::Quad:
        mesh = makeQuadMesh(o.position, o.normal, o.v_axis, o.size.x, o.size.y, uv_scale);
        break;
      case EnvObjectDesc::Type::Mesh: mesh = loadedMesh(o, load_mesh, what, parts); break;
    }
    mesh.name = o.name.empty() ? std::string(nameOf(o.type)) + std::to_string(i) : o.name;
    mesh.occluder = occluderId(occluders, o.occluder);
    if (!parts.empty()) {  // a file with its own materials (glTF): one mesh per part, the file's materials
      addMeshParts(scene, mesh, parts, what, i, o.animation.has_value());
      continue;
    }
    DiffuseMaterial mat;
    mat.color = o.material.color;
    if (o.material.texture) {
      mat.texture = int(scene.textures.size());
      scene.textures.push_back(makeTexture(*o.material.texture, what));
    }
    mesh.material = int(scene.materials.size());
    scene.materials.push_back(mat);
    scene.mesh_object.push_back(i);
    scene.placed_meshes.push_back(o.animation ? mesh : EnvMesh{});
    scene.mesh_motion.push_back(Mat4(1.0));
    scene.meshes.push_back(std::move(mesh));
  }

  for (const LightDesc& l : desc.lights) {
    Light light;
    light.radiance = l.color * l.intensity;
    light.shadows = l.shadows && l.type != LightDesc::Type::Ambient;
    light.caustics = l.caustics && l.type != LightDesc::Type::Ambient;
    switch (l.type) {
      case LightDesc::Type::Ambient: light.type = Light::Type::Ambient; break;
      case LightDesc::Type::Directional:
        light.type = Light::Type::Directional;
        light.direction = glm::normalize(l.direction);
        break;
      case LightDesc::Type::Point:
        light.type = Light::Type::Point;
        light.position = l.position;
        break;
    }
    scene.lights.push_back(light);
  }

  for (size_t i = 0; i < desc.elements.size(); ++i) {
    const ElementDesc& e = desc.elements[i];
    const std::string what = file + ": elements[" + std::to_string(i) + "] (" + e.name + ")";
    Element el;
    el.name = e.name;
    el.type = e.type == ElementDesc::Type::Lens ? ElementType::Lens : ElementType::Mirror;
    el.attached_to_observer = e.attached_to_observer;
    el.eye_rotation_centre_m = e.eye_rotation_centre_m;
    el.patches_u = e.patches_u;
    el.patches_v = e.patches_v;
    el.max_patch_fov_rad = radians(e.max_patch_fov_deg);
    el.has_outline = e.outline.has_value();
    if (e.outline) el.outline = toOutline(*e.outline);
    try {
      if (el.type == ElementType::Mirror) buildMirror(el, e);
      else buildLens(el, e, file, i, what);
    } catch (const Error& err) {
      const std::string msg = err.what();
      throw Error(msg.rfind(file, 0) == 0 ? msg : what + ": " + msg);
    }
    if (e.tessellation.mode == TessellationDesc::Mode::Grid) {
      el.tess_u = e.tessellation.n_u;
      el.tess_v = e.tessellation.n_v;
    } else {
      const int n = gridForTolerance(el.frontSurface(), el.has_outline ? &el.outline : nullptr,
                                     e.tessellation.chordal_tolerance_m);
      el.tess_u = el.tess_v = n;
    }
    scene.elements.push_back(std::move(el));
  }
  updateAttachedElements(scene, desc);

  RenderSettings& rs = scene.render;
  static_cast<RenderDesc&>(rs) = desc.render;
  if (rs.output.empty()) rs.output = "out/" + scene.name + ".png";
  animatedBounds(scene, desc);
  applyAnimation(scene, desc, 0.0);
  rs.far_distance_m = std::max(1e3, 100.0 * scene.boundsRadius());
  return scene;
}

void updateAttachedElements(Scene& scene, const SceneDesc& desc) {
  const Mat4 obs = observerToWorld(scene.observer);
  for (size_t i = 0; i < scene.elements.size() && i < desc.elements.size(); ++i) {
    Element& el = scene.elements[i];
    const ElementDesc& d = desc.elements[i];
    const Mat4 pose =
        d.animation ? motionAt(*d.animation, d.pose.position, scene.time_s) * poseMatrix(d.pose) : poseMatrix(d.pose);
    el.local_to_world = el.attached_to_observer ? obs * pose : pose;
    el.world_to_local = glm::inverse(el.local_to_world);
  }
}

bool isAnimated(const SceneDesc& desc) {
  return std::any_of(desc.environment.begin(), desc.environment.end(),
                     [](const EnvObjectDesc& o) { return bool(o.animation); }) ||
         std::any_of(desc.elements.begin(), desc.elements.end(),
                     [](const ElementDesc& e) { return bool(e.animation); });
}

namespace {

// `placed` moved rigidly by m: the anchor in double, the positions and normals rotated.
void moveMesh(const EnvMesh& placed, const Mat4& m, EnvMesh& out) {
  const Mat3 r(m);
  out.anchor = Vec3(m * Vec4(placed.anchor, 1.0));
  for (size_t i = 0; i < placed.positions.size(); ++i) out.positions[i] = glm::vec3(r * Vec3(placed.positions[i]));
  for (size_t i = 0; i < placed.normals.size(); ++i)
    out.normals[i] = glm::vec3(glm::normalize(r * Vec3(placed.normals[i])));
}

}  // namespace

bool applyAnimation(Scene& scene, const SceneDesc& desc, double t_s) {
  bool moved = false;
  scene.time_s = t_s;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const EnvObjectDesc& o = desc.environment[scene.mesh_object[m]];
    if (!o.animation) continue;
    EnvMesh& mesh = scene.meshes[m];
    const Mat4 motion = motionAt(*o.animation, o.position, t_s);
    if (motion == scene.mesh_motion[m]) continue;  // the same motion poses the same mesh
    moveMesh(scene.placed_meshes[m], motion, mesh);
    scene.mesh_motion[m] = motion;
    moved = true;
  }
  std::vector<Mat4> poses;
  for (const Element& el : scene.elements) poses.push_back(el.local_to_world);
  updateAttachedElements(scene, desc);
  for (size_t e = 0; e < poses.size(); ++e) moved = moved || poses[e] != scene.elements[e].local_to_world;
  return moved;
}

// The bounds of the scene as built, widened by every pose its animated meshes take: posed at the instants of
// sweepSamples (the keys, and between them at most kSweepStepDeg of turn apart), padded by how far a vertex
// can stray from the segment between its sampled positions in between (none for a motion without a turn),
// so that a rotation sweeping outside the key poses stays inside (the elements' positions change the bounds little; the
// scene at t = 0 holds them).
void animatedBounds(Scene& scene, const SceneDesc& desc) {
  scene.updateBounds();
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const EnvObjectDesc& o = desc.environment[scene.mesh_object[m]];
    if (!o.animation) continue;
    const EnvMesh& placed = scene.placed_meshes[m];
    double radius_m = 0;  // the farthest vertex from the pivot
    for (const glm::vec3& p : placed.positions)
      radius_m = std::max(radius_m, glm::length(placed.anchor + Vec3(p) - o.position));
    const SweepSamples sweep = sweepSamples(*o.animation);
    const Vec3 pad(radius_m * sweep.max_step_rad);
    EnvMesh moved = placed;
    for (const double t_s : sweep.times_s) {
      moveMesh(placed, motionAt(*o.animation, o.position, t_s), moved);
      for (const glm::vec3& p : moved.positions) {
        scene.bounds_min = glm::min(scene.bounds_min, moved.anchor + Vec3(p) - pad);
        scene.bounds_max = glm::max(scene.bounds_max, moved.anchor + Vec3(p) + pad);
      }
    }
  }
}

}  // namespace pvrr
