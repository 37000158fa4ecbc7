#include "pixelgym/render/mesh_data.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <utility>

namespace pixelgym::render {
namespace {

constexpr double kPi = 3.14159265358979323846;

void add_vertex(MeshData& mesh, const Eigen::Vector3f& p, const Eigen::Vector3f& n,
                const Eigen::Vector2f& uv) {
  mesh.positions.push_back(p);
  mesh.normals.push_back(n);
  mesh.texcoords.push_back(uv);
}

// A surface of revolution about z: `profile` gives (radius, z, normal radial part, normal z) for
// each ring from bottom to top.
void add_revolution(MeshData& mesh, const std::vector<Eigen::Vector4f>& profile, int segments) {
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  for (std::size_t r = 0; r < profile.size(); ++r) {
    for (int k = 0; k <= segments; ++k) {
      const double t = 2 * kPi * k / segments;
      const float c = static_cast<float>(std::cos(t));
      const float s = static_cast<float>(std::sin(t));
      const Eigen::Vector4f& ring = profile[r];
      add_vertex(mesh, {ring[0] * c, ring[0] * s, ring[1]},
                 Eigen::Vector3f(ring[2] * c, ring[2] * s, ring[3]).normalized(),
                 {static_cast<float>(k) / static_cast<float>(segments),
                  static_cast<float>(r) / static_cast<float>(profile.size() - 1)});
    }
  }
  const auto stride = static_cast<std::uint32_t>(segments + 1);
  for (std::uint32_t r = 0; r + 1 < profile.size(); ++r) {
    for (std::uint32_t k = 0; k < static_cast<std::uint32_t>(segments); ++k) {
      const std::uint32_t a = base + r * stride + k;
      const std::uint32_t b = a + stride;
      mesh.indices.insert(mesh.indices.end(), {a, a + 1, b + 1, a, b + 1, b});
    }
  }
}

// A flat disc at height z facing `up` (+1) or down (-1).
void add_disc(MeshData& mesh, float z, float up, int segments) {
  const auto centre = static_cast<std::uint32_t>(mesh.positions.size());
  add_vertex(mesh, {0, 0, z}, {0, 0, up}, {0.5F, 0.5F});
  for (int k = 0; k <= segments; ++k) {
    const double t = 2 * kPi * k / segments;
    const float c = static_cast<float>(std::cos(t));
    const float s = static_cast<float>(std::sin(t));
    add_vertex(mesh, {c, s, z}, {0, 0, up}, {0.5F + 0.5F * c, 0.5F + 0.5F * s});
  }
  for (std::uint32_t k = 0; k < static_cast<std::uint32_t>(segments); ++k) {
    if (up > 0) {
      mesh.indices.insert(mesh.indices.end(), {centre, centre + 1 + k, centre + 2 + k});
    } else {
      mesh.indices.insert(mesh.indices.end(), {centre, centre + 2 + k, centre + 1 + k});
    }
  }
}

}  // namespace

std::shared_ptr<const MeshData> make_box_mesh() {
  auto mesh = std::make_shared<MeshData>();
  const Eigen::Vector3f normals[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                      {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  for (const Eigen::Vector3f& n : normals) {
    // Two axes spanning the face, ordered so that u x v = n (counter-clockwise from outside).
    Eigen::Vector3f u =
        n.cross(std::abs(n.z()) < 0.5F ? Eigen::Vector3f(0, 0, 1) : Eigen::Vector3f(1, 0, 0));
    Eigen::Vector3f v = n.cross(u);
    const auto base = static_cast<std::uint32_t>(mesh->positions.size());
    const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (const auto& c : corners) {
      add_vertex(*mesh, 0.5F * (n + c[0] * u + c[1] * v), n,
                 {0.5F + 0.5F * c[0], 0.5F + 0.5F * c[1]});
    }
    if (u.cross(v).dot(n) > 0) {
      mesh->indices.insert(mesh->indices.end(),
                           {base, base + 1, base + 2, base, base + 2, base + 3});
    } else {
      mesh->indices.insert(mesh->indices.end(),
                           {base, base + 2, base + 1, base, base + 3, base + 2});
    }
  }
  mesh->closed = is_closed_surface(*mesh);
  return mesh;
}

std::shared_ptr<const MeshData> make_sphere_mesh(int segments) {
  auto mesh = std::make_shared<MeshData>();
  std::vector<Eigen::Vector4f> profile;
  const int rings = std::max(4, segments / 2);
  for (int i = 0; i <= rings; ++i) {
    const double a = -kPi / 2 + kPi * i / rings;
    const auto c = static_cast<float>(std::cos(a));
    const auto s = static_cast<float>(std::sin(a));
    profile.emplace_back(c, s, c, s);
  }
  add_revolution(*mesh, profile, segments);
  mesh->closed = is_closed_surface(*mesh);
  return mesh;
}

std::shared_ptr<const MeshData> make_cylinder_mesh(int segments) {
  auto mesh = std::make_shared<MeshData>();
  add_revolution(*mesh, {{1, -0.5F, 1, 0}, {1, 0.5F, 1, 0}}, segments);
  add_disc(*mesh, 0.5F, 1.0F, segments);
  add_disc(*mesh, -0.5F, -1.0F, segments);
  mesh->closed = is_closed_surface(*mesh);
  return mesh;
}

std::shared_ptr<const MeshData> make_capsule_mesh(double length_over_radius, int segments) {
  auto mesh = std::make_shared<MeshData>();
  const auto half = static_cast<float>(length_over_radius / 2);
  std::vector<Eigen::Vector4f> profile;
  const int rings = std::max(3, segments / 4);
  for (int i = 0; i <= rings; ++i) {  // bottom hemisphere
    const double a = -kPi / 2 + (kPi / 2) * i / rings;
    const auto c = static_cast<float>(std::cos(a));
    const auto s = static_cast<float>(std::sin(a));
    profile.emplace_back(c, -half + s, c, s);
  }
  for (int i = 0; i <= rings; ++i) {  // top hemisphere
    const double a = (kPi / 2) * i / rings;
    const auto c = static_cast<float>(std::cos(a));
    const auto s = static_cast<float>(std::sin(a));
    profile.emplace_back(c, half + s, c, s);
  }
  add_revolution(*mesh, profile, segments);
  mesh->closed = is_closed_surface(*mesh);
  return mesh;
}

std::shared_ptr<const MeshData> simplify_by_clustering(const MeshData& mesh, float cell) {
  using Part = MeshData::Part;
  auto result = std::make_shared<MeshData>();
  result->closed = mesh.closed;
  std::vector<Part> parts = mesh.parts;
  if (parts.empty()) {
    Part all;
    all.index_count = static_cast<std::uint32_t>(mesh.indices.size());
    parts.push_back(all);
  }
  for (const Part& part : parts) {
    // One output vertex per occupied grid cell of this part: the mean of its vertices.
    std::map<std::tuple<long, long, long>, std::uint32_t> cell_vertex;
    std::vector<std::uint32_t> counts;
    const auto first_vertex = static_cast<std::uint32_t>(result->positions.size());
    const auto cluster = [&](std::uint32_t source) {
      const Eigen::Vector3f& p = mesh.positions[source];
      const auto key = std::make_tuple(std::lround(std::floor(p.x() / cell)),
                                       std::lround(std::floor(p.y() / cell)),
                                       std::lround(std::floor(p.z() / cell)));
      auto [it, added] =
          cell_vertex.emplace(key, static_cast<std::uint32_t>(result->positions.size()));
      const Eigen::Vector3f n =
          source < mesh.normals.size() ? mesh.normals[source] : Eigen::Vector3f::UnitZ();
      if (added) {
        result->positions.push_back(p);
        result->normals.push_back(n);
        counts.push_back(1);
      } else {
        const std::uint32_t v = it->second;
        result->positions[v] += p;
        result->normals[v] += n;
        ++counts[v - first_vertex];
      }
      return it->second;
    };
    Part out = part;
    out.first_index = static_cast<std::uint32_t>(result->indices.size());
    for (std::uint32_t i = part.first_index; i + 2 < part.first_index + part.index_count; i += 3) {
      const std::uint32_t a = cluster(mesh.indices[i]);
      const std::uint32_t b = cluster(mesh.indices[i + 1]);
      const std::uint32_t c = cluster(mesh.indices[i + 2]);
      if (a != b && b != c && a != c) result->indices.insert(result->indices.end(), {a, b, c});
    }
    for (std::uint32_t v = first_vertex; v < result->positions.size(); ++v) {
      result->positions[v] /= static_cast<float>(counts[v - first_vertex]);
      const float length = result->normals[v].norm();
      result->normals[v] =
          length > 1e-12F ? Eigen::Vector3f(result->normals[v] / length) : Eigen::Vector3f::UnitZ();
    }
    out.index_count = static_cast<std::uint32_t>(result->indices.size()) - out.first_index;
    if (out.index_count > 0) result->parts.push_back(out);
  }
  return result;
}

bool is_closed_surface(const MeshData& mesh) {
  if (mesh.indices.empty() || mesh.indices.size() % 3 != 0) return false;
  Eigen::AlignedBox3f bounds;
  for (const Eigen::Vector3f& p : mesh.positions) bounds.extend(p);
  const float tolerance = std::max(1e-6F * bounds.diagonal().norm(), 1e-12F);
  // Vertices by rounded position.
  std::map<std::tuple<long, long, long>, std::uint32_t> welded;
  std::vector<std::uint32_t> id(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Eigen::Vector3f& p = mesh.positions[v];
    const auto key = std::make_tuple(std::lround(p.x() / tolerance), std::lround(p.y() / tolerance),
                                     std::lround(p.z() / tolerance));
    id[v] = welded.emplace(key, static_cast<std::uint32_t>(welded.size())).first->second;
  }
  // Directed edges and how often each is used.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  double six_volume = 0.0;
  for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
    const std::uint32_t v[3] = {mesh.indices[i], mesh.indices[i + 1], mesh.indices[i + 2]};
    if (v[0] >= id.size() || v[1] >= id.size() || v[2] >= id.size()) return false;
    const std::uint32_t a = id[v[0]], b = id[v[1]], c = id[v[2]];
    if (a == b || b == c || a == c) continue;
    ++edges[{a, b}];
    ++edges[{b, c}];
    ++edges[{c, a}];
    six_volume += mesh.positions[v[0]].cast<double>().dot(
        mesh.positions[v[1]].cast<double>().cross(mesh.positions[v[2]].cast<double>()));
  }
  if (edges.empty()) return false;
  for (const auto& [edge, count] : edges) {
    if (count != 1) return false;
    const auto reverse = edges.find({edge.second, edge.first});
    if (reverse == edges.end() || reverse->second != 1) return false;
  }
  return six_volume > 0.0;
}

std::shared_ptr<const MeshData> with_low_detail(const MeshData& fine,
                                                std::shared_ptr<const MeshData> coarse,
                                                float below_px) {
  auto mesh = std::make_shared<MeshData>(fine);
  mesh->low_detail = std::move(coarse);
  mesh->low_detail_radius = 1.0F;
  mesh->low_detail_below_px = below_px;
  return mesh;
}

}  // namespace pixelgym::render
