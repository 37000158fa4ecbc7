// Private to render/: where the shadow map looks and where shadows can fall — pure functions, no
// OpenGL.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "pixelgym/render/camera.h"
#include "pixelgym/render/scene.h"

namespace pixelgym::render {

/// The shadow map's side in texels: about one texel per image pixel, the power of two in
/// [128, 2048] at or above the larger of the camera's width and height (a map larger than the
/// image costs more to clear and sample than it shows).
int shadow_map_size(const Camera& camera);

/// The matrix from world to the shadow map's clip space: the light looks along
/// `scene.light.direction` with an orthographic box fitted to the shadow casters' bounding boxes
/// in light space, so that texels are spent only where shadows can fall. `mesh_bounds[i]` bounds
/// the mesh `scene.instances[i]` is drawn with, in mesh coordinates (one per instance). A box
/// flat along an axis is widened to 1 mm there, so the matrix stays finite. Empty when no
/// instance casts a shadow.
std::optional<Eigen::Matrix4f> fit_light_projection(
    const Scene& scene, const std::vector<Eigen::AlignedBox3f>& mesh_bounds);

/// Rectangles of floor (x-y, world units) that hold every shadow on it: each caster's bounding
/// box projected along the light onto the plane z = floor height, one rectangle per caster that
/// reaches above the floor. Clears `rectangles` first; leaves it empty when the light comes from
/// the horizon or below (it casts nothing on the floor). `mesh_bounds` as for
/// `fit_light_projection`.
void shadow_footprints(const Scene& scene, const std::vector<Eigen::AlignedBox3f>& mesh_bounds,
                       std::vector<Eigen::AlignedBox2f>& rectangles);

}  // namespace pixelgym::render
