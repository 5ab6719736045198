#include "app/gltf_check.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <png.h>
#include <vector>

#include "pvrr/base/error.h"

namespace pvrr::app {

namespace {

using json = nlohmann::json;

constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF" little endian
constexpr uint32_t kChunkJson = 0x4E4F534A;     // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;      // "BIN\0"
constexpr int kModeTriangles = 4;
constexpr unsigned kMaxImageSide = 8192;  // a texture's side, pixels: 8192 x 8192 RGB is 192 MB decoded

uint32_t u32At(const std::string& d, size_t at) {
  uint32_t v = 0;
  std::memcpy(&v, d.data() + at, 4);  // glTF is little endian, as x86
  return v;
}

// A string from the file, for messages: at most 40 characters, control bytes shown as '?'.
std::string shown(const std::string& s) {
  std::string q;
  for (char c : s.substr(0, 40)) q += (static_cast<unsigned char>(c) < 32 || c == 127) ? '?' : c;
  return "\"" + q + (s.size() > 40 ? "...\"" : "\"");
}

int base64Value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

struct ComponentType {
  int code;
  size_t size;
  bool is_float;
};
constexpr ComponentType kComponentTypes[] = {{5120, 1, false}, {5121, 1, false}, {5122, 2, false},
                                             {5123, 2, false}, {5125, 4, false}, {5126, 4, true}};

struct ElementType {
  const char* name;
  size_t components;
};
constexpr ElementType kElementTypes[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                         {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};

struct Accessor {
  const ComponentType* component = nullptr;
  const ElementType* element = nullptr;
  uint64_t count = 0;
  const std::string* bytes = nullptr;  // the buffer
  uint64_t start = 0, stride = 0;      // byte offset of element 0 in the buffer, bytes between elements
};

class GltfChecker {
 public:
  GltfChecker(const std::string& data, const std::string& path, const GltfUriReader& read_uri)
      : data_(data), path_(path), read_uri_(read_uri) {}

  GltfCounts run() {
    parseContainer();
    checkAsset();
    checkBuffers();
    checkBufferViews();
    checkAccessors();
    checkImagesAndTextures();
    checkMaterials();
    checkMeshes();
    checkNodesAndScenes();
    checkSkinsAndAnimations();
    if (counts_.triangles == 0) throw Error(path_ + ": the file holds no triangles");
    return counts_;
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw Error(path_ + ": " + where + (where.empty() ? "" : ": ") + what);
  }

  // ------------------------------------------------------------------------------------------------------
  // The container: GLB (header, JSON chunk, optional BIN chunk) or JSON text.
  void parseContainer() {
    std::string text;
    if (data_.size() >= 4 && u32At(data_, 0) == kGlbMagic) {
      if (data_.size() < 20) fail("", "the binary glTF header is cut short (" + std::to_string(data_.size()) + " bytes)");
      const uint32_t version = u32At(data_, 4), length = u32At(data_, 8);
      if (version != 2) fail("", "binary glTF version " + std::to_string(version) + ", expected 2");
      if (length != data_.size())
        fail("", "the binary glTF header says " + std::to_string(length) + " bytes, the file has " +
                     std::to_string(data_.size()) + " (cut short or padded)");
      const uint64_t json_length = u32At(data_, 12);
      if (u32At(data_, 16) != kChunkJson) fail("", "the first chunk of a binary glTF is not the JSON chunk");
      if (20 + json_length > data_.size()) fail("", "the JSON chunk runs past the end of the file");
      text = data_.substr(20, json_length);
      uint64_t at = 20 + json_length;
      if (at + 8 <= data_.size()) {
        const uint64_t bin_length = u32At(data_, at);
        if (u32At(data_, at + 4) == kChunkBin) {
          if (at + 8 + bin_length > data_.size()) fail("", "the BIN chunk runs past the end of the file");
          bin_ = data_.substr(at + 8, bin_length);
          has_bin_ = true;
        }
      }
    } else {
      size_t i = 0;
      if (data_.compare(0, 3, "\xEF\xBB\xBF") == 0) i = 3;  // a UTF-8 byte order mark
      while (i < data_.size() && std::isspace(static_cast<unsigned char>(data_[i]))) ++i;
      if (i >= data_.size() || data_[i] != '{')
        fail("", "not a glTF file (neither binary glTF, starting with \"glTF\", nor JSON text)");
      text = data_;
    }
    try {
      doc_ = json::parse(text);
    } catch (const json::exception& e) {
      std::string m = e.what();
      const size_t tag = m.find("] ");
      if (tag != std::string::npos) m = m.substr(tag + 2);
      fail("", "the glTF JSON is not valid: " + m);
    }
    if (!doc_.is_object()) fail("", "the glTF JSON is not an object");
  }

  // ------------------------------------------------------------------------------------------------------
  // Typed access. `where` is the JSON path of `obj` ("accessors[3]").
  const json& array(const char* key) const {
    static const json empty = json::array();
    const auto it = doc_.find(key);
    if (it == doc_.end()) return empty;
    if (!it->is_array()) fail(key, "expected an array");
    return *it;
  }
  const json& object(const json& item, const std::string& where) const {
    if (!item.is_object()) fail(where, "expected an object");
    return item;
  }
  bool has(const json& obj, const char* key) const { return obj.find(key) != obj.end(); }
  uint64_t integer(const json& obj, const char* key, const std::string& where, uint64_t fallback,
                   bool required = false) const {
    const auto it = obj.find(key);
    if (it == obj.end()) {
      if (required) fail(where, "\"" + std::string(key) + "\" is missing");
      return fallback;
    }
    if (!it->is_number_unsigned() && !(it->is_number_integer() && it->get<int64_t>() >= 0))
      fail(sub(where, key), "expected an integer >= 0");
    return it->get<uint64_t>();
  }
  // An index into the top-level array `target` (e.g. "accessors"), or -1 when absent and not required.
  int64_t index(const json& obj, const char* key, const std::string& where, const char* target,
                bool required = false) const {
    if (!has(obj, key) && !required) return -1;
    const uint64_t i = integer(obj, key, where, 0, required);
    const size_t n = array(target).size();
    if (i >= n) fail(sub(where, key), std::to_string(i) + " is out of range (the file has " + std::to_string(n) + " " + target + ")");
    return int64_t(i);
  }
  std::string string(const json& obj, const char* key, const std::string& where) const {
    const auto it = obj.find(key);
    if (it == obj.end()) return {};
    if (!it->is_string()) fail(where + "." + key, "expected a string");
    return it->get<std::string>();
  }
  // An array of `n` finite numbers (n = 0: any length), or empty when absent.
  std::vector<double> numbers(const json& obj, const char* key, const std::string& where, size_t n) const {
    const auto it = obj.find(key);
    if (it == obj.end()) return {};
    const std::string at = where + "." + key;
    if (!it->is_array() || (n > 0 && it->size() != n))
      fail(at, n > 0 ? "expected an array of " + std::to_string(n) + " numbers" : "expected an array of numbers");
    std::vector<double> v;
    for (const json& x : *it) {
      if (!x.is_number()) fail(at, "expected an array of numbers");
      const double d = x.get<double>();
      if (!std::isfinite(d)) fail(at, "expected finite numbers");
      v.push_back(d);
    }
    return v;
  }
  static std::string sub(const std::string& where, const char* key) { return where.empty() ? key : where + "." + key; }
  static std::string item(const char* arr, size_t i) { return std::string(arr) + "[" + std::to_string(i) + "]"; }

  // ------------------------------------------------------------------------------------------------------
  void checkAsset() const {
    const auto it = doc_.find("asset");
    if (it == doc_.end()) fail("", "\"asset\" is missing (a glTF 2.0 file has {\"asset\": {\"version\": \"2.0\"}})");
    const std::string version = string(object(*it, "asset"), "version", "asset");
    if (version.compare(0, 2, "2.") != 0) fail("asset.version", "glTF " + shown(version) + ", expected 2.x");
    const auto req = doc_.find("extensionsRequired");
    if (req != doc_.end() && req->is_array() && !req->empty())
      fail("extensionsRequired", "the file needs the extension " + (req->at(0).is_string() ? shown(req->at(0).get<std::string>()) : std::string("?")) +
                                     ", which pvrr does not read");
  }

  std::string decodeDataUri(const std::string& uri, const std::string& where) const {
    const size_t comma = uri.find(',');
    if (comma == std::string::npos || uri.rfind(";base64", comma) == std::string::npos)
      fail(where, "a data: URI without \";base64,\"");
    std::string out;
    uint32_t acc = 0;
    int bits = 0;
    for (size_t i = comma + 1; i < uri.size(); ++i) {
      const char c = uri[i];
      if (c == '=') break;
      const int v = base64Value(c);
      if (v < 0) fail(where, "the data: URI holds a character that is not base64 at " + std::to_string(i));
      acc = (acc << 6) | uint32_t(v);
      bits += 6;
      if (bits >= 8) {
        bits -= 8;
        out.push_back(char((acc >> bits) & 0xFF));
      }
    }
    return out;
  }

  // The bytes a buffer or image `uri` names: a data: URI decoded, else the external file.
  std::string uriBytes(const std::string& uri, const std::string& where) const {
    if (uri.compare(0, 5, "data:") == 0) return decodeDataUri(uri, where);
    try {
      return read_uri_(uri);
    } catch (const Error& e) {
      fail(where, e.what());
    }
  }

  void checkBuffers() {
    const json& buffers = array("buffers");
    for (size_t i = 0; i < buffers.size(); ++i) {
      const std::string where = item("buffers", i);
      const json& b = object(buffers[i], where);
      const uint64_t length = integer(b, "byteLength", where, 0, true);
      if (length == 0) fail(where + ".byteLength", "expected at least 1 byte");
      std::string bytes;
      if (has(b, "uri")) {
        bytes = uriBytes(string(b, "uri", where), where + ".uri");
      } else if (i == 0 && has_bin_) {
        bytes = bin_;
      } else {
        fail(where, "no \"uri\" and no binary chunk to hold the data");
      }
      if (bytes.size() < length)
        fail(where, "byteLength is " + std::to_string(length) + ", the data has " + std::to_string(bytes.size()) + " bytes");
      buffers_.push_back(std::move(bytes));
      buffer_lengths_.push_back(length);
    }
  }

  void checkBufferViews() const {
    const json& views = array("bufferViews");
    for (size_t i = 0; i < views.size(); ++i) {
      const std::string where = item("bufferViews", i);
      const json& v = object(views[i], where);
      const int64_t b = index(v, "buffer", where, "buffers", true);
      const uint64_t offset = integer(v, "byteOffset", where, 0), length = integer(v, "byteLength", where, 0, true);
      if (length == 0) fail(where + ".byteLength", "expected at least 1 byte");
      if (offset > buffer_lengths_[size_t(b)] || length > buffer_lengths_[size_t(b)] - offset)
        fail(where, "bytes " + std::to_string(offset) + " + " + std::to_string(length) + " run past the end of buffers[" +
                        std::to_string(b) + "] (" + std::to_string(buffer_lengths_[size_t(b)]) + " bytes)");
      if (has(v, "byteStride")) {
        const uint64_t s = integer(v, "byteStride", where, 0);
        if (s < 4 || s > 252 || s % 4 != 0) fail(where + ".byteStride", "expected a multiple of 4 in [4, 252], got " + std::to_string(s));
      }
    }
  }

  void checkAccessors() {
    const json& accessors = array("accessors");
    const json& views = array("bufferViews");
    for (size_t i = 0; i < accessors.size(); ++i) {
      const std::string where = item("accessors", i);
      const json& a = object(accessors[i], where);
      Accessor acc;
      const uint64_t code = integer(a, "componentType", where, 0, true);
      for (const ComponentType& c : kComponentTypes) acc.component = c.code == int(code) ? &c : acc.component;
      if (!acc.component) fail(where + ".componentType", std::to_string(code) + " is not a glTF component type");
      const std::string type = string(a, "type", where);
      for (const ElementType& e : kElementTypes) acc.element = type == e.name ? &e : acc.element;
      if (!acc.element) fail(where + ".type", shown(type) + " is not a glTF accessor type");
      acc.count = integer(a, "count", where, 0, true);
      if (acc.count == 0) fail(where + ".count", "expected at least 1 element");
      if (has(a, "sparse")) fail(where + ".sparse", "sparse accessors are not read by pvrr");
      const int64_t view_index = index(a, "bufferView", where, "bufferViews");
      if (view_index < 0) fail(where, "no bufferView (accessors without data are not read by pvrr)");
      const json& view = views[size_t(view_index)];
      const uint64_t offset = integer(a, "byteOffset", where, 0);
      const uint64_t view_length = integer(view, "byteLength", "", 0);
      const uint64_t element_size = acc.component->size * acc.element->components;
      acc.stride = has(view, "byteStride") ? integer(view, "byteStride", "", 0) : element_size;
      if (offset % acc.component->size != 0) fail(where + ".byteOffset", "not a multiple of the component size");
      // offset + stride (count - 1) + element size <= the view's length, without overflow.
      if (offset > view_length || acc.count > view_length || element_size > view_length - offset ||
          acc.stride * (acc.count - 1) > view_length - offset - element_size)
        fail(where, std::to_string(acc.count) + " elements of " + std::to_string(element_size) + " bytes from byte " +
                        std::to_string(offset) + " run past the end of bufferViews[" + std::to_string(view_index) + "] (" +
                        std::to_string(view_length) + " bytes)");
      acc.bytes = &buffers_[size_t(index(view, "buffer", "", "buffers"))];
      acc.start = integer(view, "byteOffset", "", 0) + offset;
      if (acc.component->is_float) checkFinite(acc, where);
      accessors_.push_back(acc);
    }
  }

  void checkFinite(const Accessor& a, const std::string& where) const {
    for (uint64_t e = 0; e < a.count; ++e)
      for (size_t k = 0; k < a.element->components; ++k) {
        float v = 0;
        std::memcpy(&v, a.bytes->data() + a.start + e * a.stride + 4 * k, 4);
        if (!std::isfinite(v))
          fail(where, "element " + std::to_string(e) + ": component " + std::to_string(k) + " is not a finite number");
      }
  }

  uint64_t indexValue(const Accessor& a, uint64_t e) const {
    const char* p = a.bytes->data() + a.start + e * a.stride;
    if (a.component->size == 1) return static_cast<unsigned char>(*p);
    if (a.component->size == 2) {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
  }

  // ------------------------------------------------------------------------------------------------------
  // VTK's PNG reader crashes on a damaged PNG (a CRC error, data cut short): the image is decoded here first,
  // with libpng, which VTK uses too. JPEG is refused: its decoder is not guarded here.
  void checkPng(const std::string& bytes, const std::string& where) const {
    if (bytes.compare(0, 3, "\xFF\xD8\xFF") == 0) fail(where, "a JPEG image; pvrr reads PNG textures only (convert it)");
    if (bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) fail(where, "not a PNG image");
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) {
      const std::string reason = png.message;
      png_image_free(&png);
      fail(where, "the PNG image cannot be read (libpng: " + reason + ")");
    }
    if (png.width == 0 || png.height == 0 || png.width > kMaxImageSide || png.height > kMaxImageSide) {
      png_image_free(&png);
      fail(where, "a PNG image of " + std::to_string(png.width) + " x " + std::to_string(png.height) +
                      " pixels (at most " + std::to_string(kMaxImageSide) + " on a side)");
    }
    png.format = PNG_FORMAT_RGB;
    std::vector<unsigned char> pixels(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, pixels.data(), 0, nullptr)) {
      const std::string reason = png.message;
      png_image_free(&png);
      fail(where, "the PNG image cannot be decoded (libpng: " + reason + ")");
    }
  }

  void checkImagesAndTextures() const {
    const json& images = array("images");
    for (size_t i = 0; i < images.size(); ++i) {
      const std::string where = item("images", i);
      const json& im = object(images[i], where);
      std::string bytes;
      if (has(im, "uri")) {
        bytes = uriBytes(string(im, "uri", where), where + ".uri");
      } else {
        const int64_t v = index(im, "bufferView", where, "bufferViews", true);
        const json& view = array("bufferViews")[size_t(v)];
        const std::string& buffer = buffers_[size_t(index(view, "buffer", "", "buffers"))];
        bytes = buffer.substr(integer(view, "byteOffset", "", 0), integer(view, "byteLength", "", 0));
      }
      checkPng(bytes, where);
    }
    const json& textures = array("textures");
    for (size_t i = 0; i < textures.size(); ++i) {
      const std::string where = item("textures", i);
      const json& t = object(textures[i], where);
      index(t, "source", where, "images", true);
      index(t, "sampler", where, "samplers");
    }
  }

  void checkTextureInfo(const json& m, const char* key, const std::string& where, bool base_colour) const {
    const auto it = m.find(key);
    if (it == m.end()) return;
    const std::string at = where + "." + key;
    index(object(*it, at), "index", at, "textures", true);
    if (base_colour && integer(*it, "texCoord", at, 0) != 0)
      fail(at + ".texCoord", "only TEXCOORD_0 is read by pvrr");
  }

  void checkMaterials() const {
    const json& materials = array("materials");
    for (size_t i = 0; i < materials.size(); ++i) {
      const std::string where = item("materials", i);
      const json& m = object(materials[i], where);
      for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"}) checkTextureInfo(m, key, where, false);
      const auto pbr = m.find("pbrMetallicRoughness");
      if (pbr == m.end()) continue;
      const std::string at = where + ".pbrMetallicRoughness";
      object(*pbr, at);
      for (double c : numbers(*pbr, "baseColorFactor", at, 4))
        if (c < 0 || c > 1) fail(at + ".baseColorFactor", "expected numbers in [0, 1]");
      checkTextureInfo(*pbr, "baseColorTexture", at, true);
      checkTextureInfo(*pbr, "metallicRoughnessTexture", at, false);
    }
  }

  // ------------------------------------------------------------------------------------------------------
  const Accessor& accessorAt(const json& obj, const char* key, const std::string& where) const {
    return accessors_[size_t(index(obj, key, where, "accessors", true))];
  }

  void checkPrimitive(const json& p, const std::string& where) {
    if (integer(p, "mode", where, kModeTriangles) != kModeTriangles)
      fail(where + ".mode", "only triangle lists (mode 4) are read by pvrr");
    const auto attrs = p.find("attributes");
    if (attrs == p.end() || !attrs->is_object()) fail(where, "\"attributes\" is missing");
    const std::string at = where + ".attributes";
    const Accessor& pos = accessorAt(*attrs, "POSITION", at);
    if (pos.element->components != 3 || !pos.component->is_float || pos.element != &kElementTypes[2])
      fail(at + ".POSITION", "expected a VEC3 float accessor");
    for (auto it = attrs->begin(); it != attrs->end(); ++it) {
      const std::string name = it.key(), aat = at + "." + name;
      const Accessor& a = accessorAt(*attrs, name.c_str(), at);
      if (a.count != pos.count)
        fail(aat, std::to_string(a.count) + " elements, POSITION has " + std::to_string(pos.count));
      // What VTK turns into normals and texture coordinates must have their number of components.
      if (name == "NORMAL" && (a.element != &kElementTypes[2] || !a.component->is_float))
        fail(aat, "expected a VEC3 float accessor");
      if (name.rfind("TEXCOORD_", 0) == 0 && a.element != &kElementTypes[1]) fail(aat, "expected a VEC2 accessor");
      if (name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0)
        fail(aat, "skinned meshes are not read by pvrr");
    }
    if (has(p, "targets")) fail(where + ".targets", "morph targets are not read by pvrr");
    index(p, "material", where, "materials");
    uint64_t corners = pos.count;
    if (has(p, "indices")) {
      const Accessor& ind = accessorAt(p, "indices", where);
      if (ind.component->is_float || ind.element->components != 1 || ind.component->code == 5120 || ind.component->code == 5122)
        fail(where + ".indices", "expected a SCALAR accessor of unsigned integers");
      for (uint64_t e = 0; e < ind.count; ++e) {
        const uint64_t v = indexValue(ind, e);
        if (v >= pos.count)
          fail(where + ".indices", "element " + std::to_string(e) + ": vertex index " + std::to_string(v) +
                                       " is out of range (POSITION has " + std::to_string(pos.count) + " vertices)");
      }
      corners = ind.count;
    }
    if (corners % 3 != 0) fail(where, std::to_string(corners) + " corners do not make whole triangles");
    counts_.triangles += corners / 3;
    ++counts_.primitives;
  }

  void checkMeshes() {
    const json& meshes = array("meshes");
    for (size_t i = 0; i < meshes.size(); ++i) {
      const std::string where = item("meshes", i);
      const json& m = object(meshes[i], where);
      const auto prims = m.find("primitives");
      if (prims == m.end() || !prims->is_array() || prims->empty()) fail(where, "expected \"primitives\": a non-empty array");
      for (size_t p = 0; p < prims->size(); ++p) {
        const std::string at = where + ".primitives[" + std::to_string(p) + "]";
        checkPrimitive(object(prims->at(p), at), at);
      }
    }
  }

  // The nodes form a forest (VTK walks it recursively: a cycle would not end).
  void checkNodesAndScenes() const {
    const json& nodes = array("nodes");
    std::vector<int64_t> parent(nodes.size(), -1);
    for (size_t i = 0; i < nodes.size(); ++i) {
      const std::string where = item("nodes", i);
      const json& n = object(nodes[i], where);
      index(n, "mesh", where, "meshes");
      index(n, "skin", where, "skins");
      index(n, "camera", where, "cameras");
      numbers(n, "matrix", where, 16);
      numbers(n, "translation", where, 3);
      numbers(n, "rotation", where, 4);
      numbers(n, "scale", where, 3);
      numbers(n, "weights", where, 0);
      const auto children = n.find("children");
      if (children == n.end()) continue;
      if (!children->is_array()) fail(where + ".children", "expected an array");
      for (size_t k = 0; k < children->size(); ++k) {
        const std::string at = where + ".children[" + std::to_string(k) + "]";
        const json& c = children->at(k);
        if (!c.is_number_unsigned() || c.get<uint64_t>() >= nodes.size())
          fail(at, "expected a node index below " + std::to_string(nodes.size()));
        const size_t child = c.get<size_t>();
        if (parent[child] >= 0 || child == i) fail(at, "node " + std::to_string(child) + " has a second parent");
        parent[child] = int64_t(i);
      }
    }
    for (size_t i = 0; i < nodes.size(); ++i) {
      size_t steps = 0;
      for (int64_t p = parent[i]; p >= 0; p = parent[size_t(p)])
        if (++steps > nodes.size()) fail(item("nodes", i), "the node is its own ancestor (a cycle of children)");
    }
    const json& scenes = array("scenes");
    for (size_t s = 0; s < scenes.size(); ++s) {
      const std::string where = item("scenes", s);
      const json& sc = object(scenes[s], where);
      const auto list = sc.find("nodes");
      if (list == sc.end()) continue;
      if (!list->is_array()) fail(where + ".nodes", "expected an array");
      for (const json& n : *list)
        if (!n.is_number_unsigned() || n.get<uint64_t>() >= nodes.size())
          fail(where + ".nodes", "expected node indices below " + std::to_string(nodes.size()));
    }
    index(doc_, "scene", "", "scenes");
  }

  void checkSkinsAndAnimations() const {
    // VTK applies skins to the geometry; pvrr shows the rest pose of rigid parts only.
    if (!array("skins").empty()) fail("skins", "skinned meshes are not read by pvrr");
    const json& animations = array("animations");
    for (size_t i = 0; i < animations.size(); ++i) {
      const std::string where = item("animations", i);
      const json& a = object(animations[i], where);
      const auto samplers = a.find("samplers");
      const auto channels = a.find("channels");
      if (samplers == a.end() || !samplers->is_array() || channels == a.end() || !channels->is_array())
        fail(where, "expected \"samplers\" and \"channels\" arrays");
      for (size_t k = 0; k < samplers->size(); ++k) {
        const std::string at = where + ".samplers[" + std::to_string(k) + "]";
        const json& s = object(samplers->at(k), at);
        index(s, "input", at, "accessors", true);
        index(s, "output", at, "accessors", true);
      }
      for (size_t k = 0; k < channels->size(); ++k) {
        const std::string at = where + ".channels[" + std::to_string(k) + "]";
        const json& c = object(channels->at(k), at);
        if (integer(c, "sampler", at, 0, true) >= samplers->size()) fail(at + ".sampler", "out of range");
        const auto target = c.find("target");
        if (target == c.end()) fail(at, "\"target\" is missing");
        index(object(*target, at + ".target"), "node", at + ".target", "nodes");
      }
    }
  }

  const std::string& data_;
  const std::string& path_;
  const GltfUriReader& read_uri_;
  json doc_;
  std::string bin_;
  bool has_bin_ = false;
  std::vector<std::string> buffers_;
  std::vector<uint64_t> buffer_lengths_;
  std::vector<Accessor> accessors_;
  GltfCounts counts_;
};

}  // namespace

GltfCounts checkGltfData(const std::string& data, const std::string& path, const GltfUriReader& read_uri) {
  return GltfChecker(data, path, read_uri).run();
}

}  // namespace pvrr::app
