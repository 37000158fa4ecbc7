// Private to render/: which mesh an instance is drawn with (level of detail) and whether its
// faces turned away may be culled — pure functions, no OpenGL.
#pragma once

#include <memory>

#include "pixelgym/render/camera.h"
#include "pixelgym/render/mesh_data.h"
#include "pixelgym/render/scene.h"

namespace pixelgym::render {

/// The mesh to draw `instance` with through `camera`: its mesh's `low_detail` when the round
/// cross-section (`low_detail_radius` times the smaller of the x and y scales) at the instance's
/// distance from the camera covers fewer than `low_detail_below_px` pixels of the image's height,
/// else its own mesh. A reference to `instance.mesh` or to its `low_detail`.
const std::shared_ptr<const MeshData>& select_detail(const Instance& instance,
                                                     const Camera& camera);

/// Whether faces of `mesh` drawn as `instance` that are turned away from the viewer may be
/// culled: a closed mesh not mirrored by its scale (a mirror turns its winding inside out).
inline bool cullable(const Instance& instance, const MeshData& mesh) {
  return mesh.closed && instance.scale.prod() > 0.0F;
}

}  // namespace pixelgym::render
