#pragma once
// The texture units of the environment shading's maps, one plan for every pass that binds them: the last units
// of GL_MAX_TEXTURE_IMAGE_UNITS, so that they never meet the element passes' low units (impostor_maps.h).
namespace pvrr::gl::units {

// The shadow maps: the depth maps, then the lens depths and transmittances (three units).
inline int shadowMaps(int max_texture_units) { return max_texture_units - 3; }
// The caustic light maps (one 2D array).
inline int causticMaps(int max_texture_units) { return max_texture_units - 4; }
// The ambient occlusion volumes (one 3D texture).
inline int aoVolume(int max_texture_units) { return max_texture_units - 5; }

}  // namespace pvrr::gl::units
