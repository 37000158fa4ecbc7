// MeshData: triangles as the renderer draws them, and the primitive shapes.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

namespace pixelgym::render {

/// An immutable triangle mesh for drawing. Shared by every instance and scene that uses it; the
/// renderer uploads it to the GPU once per context.
struct MeshData {
  /// A run of triangles with one colour (a mesh file's material); `has_color` false means the
  /// instance's material colour applies.
  struct Part {
    /// Position of the run's first index in `indices`.
    std::uint32_t first_index = 0;
    /// Indices in the run: three per triangle.
    std::uint32_t index_count = 0;
    /// The part's colour, RGBA in [0, 1], used when `has_color`.
    Eigen::Vector4f rgba{1.0F, 1.0F, 1.0F, 1.0F};
    bool has_color = false;
  };

  /// Vertex positions, in mesh units.
  std::vector<Eigen::Vector3f> positions;
  /// Unit normals, one per position (a vertex without one is drawn with +z).
  std::vector<Eigen::Vector3f> normals;
  /// Empty, or one per position (for textured materials).
  std::vector<Eigen::Vector2f> texcoords;
  /// Three per triangle, indexing `positions`.
  std::vector<std::uint32_t> indices;
  /// Empty means one part covering every index.
  std::vector<Part> parts;

  /// A coarser version drawn instead when the instance is small on screen: when
  /// `low_detail_radius` (in mesh units) times the smaller of the instance's x and y scales
  /// covers fewer than `low_detail_below_px` pixels. (The x-y cross-section is what a round
  /// primitive's segment count must resolve.) Null for none. Shadows are cast by one level
  /// coarser than the camera draws, when there is one.
  std::shared_ptr<const MeshData> low_detail;
  /// The radius, in mesh units, whose size on screen chooses `low_detail` (see above).
  float low_detail_radius = 1.0F;
  /// The size on screen, in pixels of the image's height, below which `low_detail` is drawn; 0
  /// never draws it for the camera (it may still cast shadows).
  float low_detail_below_px = 0.0F;

  /// A closed, outward-wound surface (see `is_closed_surface`): faces turned away from a viewer
  /// always lie behind faces turned toward it, so the renderer culls them. False draws every
  /// face. Primitives are closed; `simplify_by_clustering` keeps its source's flag.
  bool closed = false;

  /// indices.size() / 3.
  std::size_t triangle_count() const { return indices.size() / 3; }
};

/// Whether `mesh` bounds a volume with every triangle counter-clockwise seen from outside: with
/// vertices matched by position (to a millionth of the mesh's size, so that seams with split
/// normals or texture coordinates join), every edge is used exactly once in each direction, and
/// the enclosed volume is positive. Degenerate triangles are ignored.
bool is_closed_surface(const MeshData& mesh);

/// Unit primitives, centred at the origin and closed; instances scale them. Cylinders and
/// capsules lie along z. `segments` sets the smoothness of round shapes (segments around z).
/// A 1 x 1 x 1 box.
std::shared_ptr<const MeshData> make_box_mesh();
/// A sphere of radius 1.
std::shared_ptr<const MeshData> make_sphere_mesh(int segments = 24);
/// A cylinder of radius 1 and length 1, capped at both ends.
std::shared_ptr<const MeshData> make_cylinder_mesh(int segments = 24);
/// A capsule of radius 1 whose cylindrical part is `length / radius` long (capsules do not scale
/// uniformly, so each aspect ratio is its own mesh).
std::shared_ptr<const MeshData> make_capsule_mesh(double length_over_radius, int segments = 24);

/// A simplified copy of `mesh` for drawing small on screen: vertices are snapped to a grid of
/// `cell` (mesh units) and merged within each part (so colours stay), triangles that collapse are
/// dropped, and normals are averaged. Vertex clustering keeps the silhouette to about one cell.
/// The copy keeps `mesh.closed`: every triangle keeps its orientation, so a closed surface's
/// faces turned away from a viewer stay hidden, to about one cell, even where parts no longer
/// share vertices.
std::shared_ptr<const MeshData> simplify_by_clustering(const MeshData& mesh, float cell);

/// A copy of `fine` that is drawn as `coarse` when its round cross-section (radius 1 in mesh
/// units) covers fewer than `below_px` pixels of radius on screen.
std::shared_ptr<const MeshData> with_low_detail(const MeshData& fine,
                                                std::shared_ptr<const MeshData> coarse,
                                                float below_px);

}  // namespace pixelgym::render
