// Scene: what to draw — plain data, no OpenGL (the renderer turns it into pixels).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/render/image_io.h"
#include "pixelgym/render/mesh_data.h"

namespace pixelgym::render {

/// An image in memory to draw as a texture (the sky's or the floor's), numbered: no two
/// TextureImages of a process share a serial, so the renderer keys what it uploads and caches by
/// it. Immutable once made.
class TextureImage {
 public:
  /// Takes `image` (RGB or gray, 8 bits; RGBA's alpha is dropped). Throws std::invalid_argument
  /// for an empty image or one whose pixel count disagrees with its size.
  static std::shared_ptr<const TextureImage> make(Image image);

  const Image& image() const { return image_; }
  /// This image's number, unique in the process.
  std::uint64_t serial() const { return serial_; }

 private:
  TextureImage(Image image, std::uint64_t serial) : image_(std::move(image)), serial_(serial) {}

  Image image_;
  std::uint64_t serial_;
};

/// How a surface looks. Colours are linear RGB in [0, 1].
struct RenderMaterial {
  /// The colour of mesh parts without one of their own. Its alpha is ignored: everything is drawn
  /// opaque.
  Eigen::Vector4f base_color{0.7F, 0.7F, 0.7F, 1.0F};
  /// Strength of the white highlight, 0 (matte) to 1.
  float specular = 0.3F;
  /// The Blinn-Phong exponent: larger gives a smaller, sharper highlight.
  float shininess = 32.0F;
  /// A PNG multiplied into the base colour through the mesh's texture coordinates; empty for none.
  std::string texture_path;
  /// Added to the surface's colour (its part colours, base colour and texture) before lighting,
  /// the sum clamped to [0, 1]: how visual variation recolours a body whatever its colour source.
  Eigen::Vector3f color_offset = Eigen::Vector3f::Zero();
};

/// One drawn copy of a mesh.
struct Instance {
  /// What to draw, shared; Renderer::render refuses an instance without one.
  std::shared_ptr<const MeshData> mesh;
  /// Applied before the pose: primitives are unit-sized and scaled here.
  Eigen::Vector3f scale{1.0F, 1.0F, 1.0F};
  /// The mesh frame's pose in the world.
  Eigen::Isometry3f X_world_instance = Eigen::Isometry3f::Identity();
  RenderMaterial material;
  /// Written to segmentation images; 0 is the background.
  int segmentation_id = 0;
  /// False for things that should not darken others (markers).
  bool casts_shadow = true;
};

/// A directional light with an ambient term.
struct Light {
  /// Direction the light travels (from the light towards the scene), in world coordinates. The
  /// default comes from above and from the -y side, where task cameras usually stand, so that
  /// the faces they see are lit.
  Eigen::Vector3f direction{-0.35F, 0.5F, -0.8F};
  /// The direct light's colour, which multiplies the diffuse term and the highlight.
  Eigen::Vector3f color{0.7F, 0.7F, 0.67F};
  /// Light that reaches every surface alike, in shadow or not.
  Eigen::Vector3f ambient{0.4F, 0.4F, 0.43F};
};

/// The ground: an infinite checkerboard in the plane z = height.
struct Floor {
  /// False draws no floor (the sky shows below the horizon too).
  bool enabled = true;
  /// The plane's height, m.
  float height_m = 0.0F;
  /// The side of one checker tile, m.
  float tile_m = 0.25F;
  /// The two tile colours.
  Eigen::Vector3f color_a{0.32F, 0.36F, 0.42F};
  Eigen::Vector3f color_b{0.42F, 0.46F, 0.52F};
  /// An image drawn instead of the checker, tinted by color_a, one copy (mirrored at each edge)
  /// every 2 tile_m; null for the checker.
  std::shared_ptr<const TextureImage> image;
  /// How much of the floor covers the sky behind it, in [0, 1]: below 1 the background shows
  /// through (the Distracting Control Suite's see-through ground). Depth and segmentation still
  /// see the floor.
  float opacity = 1.0F;
};

/// The background: a vertical gradient from the horizon colour to the zenith colour, or an image.
struct Sky {
  /// The colour at and below the horizon.
  Eigen::Vector3f horizon{0.78F, 0.84F, 0.92F};
  /// The colour straight up.
  Eigen::Vector3f zenith{0.38F, 0.55F, 0.78F};
  /// An image drawn instead of the gradient, on the faces of a cube around the camera (by view
  /// direction, so it turns with the camera and does not move with it): one copy centred on each
  /// face's axis spans `image_span_deg` seen from the camera (mirrored at its edges, so that
  /// copies meet without seams), the horizon at mid-height of the side faces; null for the
  /// gradient.
  std::shared_ptr<const TextureImage> image;
  float image_span_deg = 60.0F;
};

/// Everything a frame shows.
struct Scene {
  /// What to draw, in any order.
  std::vector<Instance> instances;
  Light light;
  Floor floor;
  Sky sky;
  /// Shadows of instances from the light onto everything (the floor included).
  bool shadows = true;
};

}  // namespace pixelgym::render
