#include "immerse/walls/WallSurface.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/GmshReader.hpp"
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

namespace {

// Where the closest point of a triangle lies: its interior, a vertex k (VertexK) or the edge from vertex k (EdgeK).
enum class WsRegion { Face, Vertex0, Vertex1, Vertex2, Edge0, Edge1, Edge2 };

// The closest point of triangle abc to p and its region (Ericson, Real-Time Collision Detection, §5.1.5).
Vec3 ws_closest_point(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, WsRegion& region) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return region = WsRegion::Vertex0, a;
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return region = WsRegion::Vertex1, b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return region = WsRegion::Edge0, a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return region = WsRegion::Vertex2, c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return region = WsRegion::Edge2, a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return region = WsRegion::Edge1, b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1 / (va + vb + vc);
  region = WsRegion::Face;
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Squared distance from p to the box [lo, hi] (0 inside).
double ws_box_distance2(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  double s = 0;
  for (int k = 0; k < 3; ++k) {
    const double e = std::max({lo[k] - p[k], 0.0, p[k] - hi[k]});
    s += e * e;
  }
  return s;
}

// The angle between u and v (robust for small and large angles).
double ws_angle(const Vec3& u, const Vec3& v) { return std::atan2(norm(cross(u, v)), dot(u, v)); }

// Whether the segment pq passes through the interior of triangle abc, clear of its plane and edges by more than 1e-9
// of the longest edge (nearly coplanar neighbours, which round-off would make cross, do not).
bool ws_edge_crosses(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double size = std::sqrt(std::max({dot(b - a, b - a), dot(c - b, c - b), dot(a - c, a - c), dot(q - p, q - p)}));
  const double tol = 1e-9 * size;
  const Vec3 n = normalized(cross(b - a, c - a));
  const double dp = dot(p - a, n), dq = dot(q - a, n);
  if (!((dp > tol && dq < -tol) || (dp < -tol && dq > tol))) return false;
  const Vec3 x = p + (dp / (dp - dq)) * (q - p);
  for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}})
    if (!(dot(cross(v - u, x - u), n) > tol * norm(v - u))) return false;
  return true;
}

}  // namespace

WallSurface::WallSurface(std::vector<Vec3> vertices, std::vector<std::array<int, 3>> triangles,
                         const std::string& label)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)) {
  const auto fail = [&](const std::string& what) { throw InputError(label + ": " + what); };
  const auto tri_text = [&](std::size_t t) { return "triangle " + std::to_string(t); };
  if (triangles_.empty()) fail("holds no triangles: must be a closed surface");
  const int nv = static_cast<int>(vertices_.size());
  for (const Vec3& v : vertices_)
    if (!isfinite(v)) fail("vertex " + point_text(v) + " is not finite");
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    for (int i : triangles_[t])
      if (i < 0 || i >= nv) fail(tri_text(t) + " refers to vertex " + std::to_string(i) + " of " + std::to_string(nv));
  // Zero area: as for membranes, half the cross product no larger than 1e-12 of the longest edge squared.
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    const auto& tr = triangles_[t];
    const Vec3 a = vertices_[tr[0]], b = vertices_[tr[1]], c = vertices_[tr[2]];
    const double longest = std::max({dot(b - a, b - a), dot(c - b, c - b), dot(a - c, a - c)});
    if (tr[0] == tr[1] || tr[1] == tr[2] || tr[2] == tr[0] || !(0.5 * norm(cross(b - a, c - a)) > 1e-12 * longest))
      fail(tri_text(t) + " (corners " + point_text(a) + ", " + point_text(b) + ", " + point_text(c) + ") has zero area");
  }
  // Every edge in exactly two triangles, run in opposite directions by them; the defect of the lowest triangle.
  struct Use {
    std::size_t triangle;
    int from;
  };
  std::unordered_map<std::uint64_t, std::vector<Use>> edges;
  const auto key = [](int a, int b) { return (std::uint64_t(std::min(a, b)) << 32) | std::uint64_t(std::max(a, b)); };
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k)
      edges[key(triangles_[t][k], triangles_[t][(k + 1) % 3])].push_back({t, triangles_[t][k]});
  std::vector<std::pair<std::size_t, std::string>> defects;
  for (const auto& [k, uses] : edges) {
    const int a = static_cast<int>(k >> 32), b = static_cast<int>(k & 0xffffffffu);
    const std::string edge = "edge " + point_text(vertices_[a]) + " - " + point_text(vertices_[b]);
    if (uses.size() == 1)
      defects.emplace_back(uses[0].triangle, "the surface is open: " + edge + " of " + tri_text(uses[0].triangle) +
                                                 " belongs to no other triangle (every edge must join two)");
    else if (uses.size() > 2)
      defects.emplace_back(uses[0].triangle, edge + " of " + tri_text(uses[0].triangle) + " is shared by " +
                                                 std::to_string(uses.size()) +
                                                 " triangles: must be two (the surface is non-manifold)");
    else if (uses[0].from == uses[1].from)
      defects.emplace_back(std::max(uses[0].triangle, uses[1].triangle),
                           "triangles " + std::to_string(std::min(uses[0].triangle, uses[1].triangle)) + " and " +
                               std::to_string(std::max(uses[0].triangle, uses[1].triangle)) +
                               " are oriented inconsistently: both run " + edge +
                               " the same way (every triangle must be counter-clockwise seen from the same side)");
  }
  if (!defects.empty()) fail(std::min_element(defects.begin(), defects.end())->second);
  // The hierarchy of bounding boxes; the bounding box of the surface is that of its root.
  const std::size_t nt = triangles_.size();
  std::vector<Vec3> centroid(nt);
  order_.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tr = triangles_[t];
    centroid[t] = (vertices_[tr[0]] + vertices_[tr[1]] + vertices_[tr[2]]) / 3.0;
    order_[t] = static_cast<int>(t);
  }
  nodes_.reserve(2 * nt);
  nodes_.push_back({});
  build(0, 0, static_cast<int>(nt), centroid);
  lower_ = nodes_[0].lo;
  upper_ = nodes_[0].hi;
  if (const auto pair = crossing_triangles())
    fail("triangles " + std::to_string(pair->first) + " and " + std::to_string(pair->second) +
         " intersect: the surface crosses itself");
  // Outward: a negative enclosed volume flips every triangle.
  double six_v = 0;
  for (const auto& tr : triangles_) six_v += dot(vertices_[tr[0]], cross(vertices_[tr[1]], vertices_[tr[2]]));
  if (six_v < 0)
    for (auto& tr : triangles_) std::swap(tr[1], tr[2]);
  volume_ = std::abs(six_v) / 6;
  if (!(volume_ > 0)) fail("encloses no volume");
  // Pseudonormals: faces, edges (the sum of the two faces' normals) and vertices (weighted by the corner angles).
  face_normal_.resize(nt);
  edge_normal_.resize(nt);
  vertex_normal_.assign(vertices_.size(), Vec3{});
  std::unordered_map<std::uint64_t, Vec3> edge_sum;
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tr = triangles_[t];
    const Vec3 a = vertices_[tr[0]], b = vertices_[tr[1]], c = vertices_[tr[2]];
    face_normal_[t] = normalized(cross(b - a, c - a));
    vertex_normal_[tr[0]] += ws_angle(b - a, c - a) * face_normal_[t];
    vertex_normal_[tr[1]] += ws_angle(c - b, a - b) * face_normal_[t];
    vertex_normal_[tr[2]] += ws_angle(a - c, b - c) * face_normal_[t];
    for (int k = 0; k < 3; ++k) edge_sum[key(tr[k], tr[(k + 1) % 3])] += face_normal_[t];
  }
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) edge_normal_[t][k] = edge_sum[key(triangles_[t][k], triangles_[t][(k + 1) % 3])];
}

std::optional<std::pair<std::size_t, std::size_t>> WallSurface::crossing_triangles() const {
  // Triangles sharing no vertex whose boxes overlap (found in the hierarchy), lowest pair first.
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    const auto& s = triangles_[t];
    Vec3 lo = vertices_[s[0]], hi = lo;
    for (int v : s)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], vertices_[v][k]), hi[k] = std::max(hi[k], vertices_[v][k]);
    std::size_t found = triangles_.size();
    int stack[128], top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      bool overlap = true;
      for (int k = 0; k < 3; ++k) overlap = overlap && node.lo[k] <= hi[k] && lo[k] <= node.hi[k];
      if (!overlap) continue;
      if (node.count == 0) {
        stack[top++] = node.first;
        stack[top++] = node.first + 1;
        continue;
      }
      for (int i = node.first; i < node.first + node.count; ++i) {
        const auto u = static_cast<std::size_t>(order_[i]);
        if (u <= t || u >= found) continue;
        const auto& r = triangles_[u];
        if (std::any_of(s.begin(), s.end(), [&](int v) { return v == r[0] || v == r[1] || v == r[2]; })) continue;
        const auto P = [&](const std::array<int, 3>& x, int k) { return vertices_[x[k]]; };
        bool crossing = false;
        for (int k = 0; k < 3 && !crossing; ++k)
          crossing = ws_edge_crosses(P(s, k), P(s, (k + 1) % 3), P(r, 0), P(r, 1), P(r, 2)) ||
                     ws_edge_crosses(P(r, k), P(r, (k + 1) % 3), P(s, 0), P(s, 1), P(s, 2));
        if (crossing) found = u;
      }
    }
    if (found < triangles_.size()) return std::pair{t, found};
  }
  return std::nullopt;
}

void WallSurface::build(int node, int begin, int end, const std::vector<Vec3>& centroid) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf}, clo = lo, chi = hi;
  for (int i = begin; i < end; ++i) {
    for (int v : triangles_[order_[i]])
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], vertices_[v][k]), hi[k] = std::max(hi[k], vertices_[v][k]);
    for (int k = 0; k < 3; ++k)
      clo[k] = std::min(clo[k], centroid[order_[i]][k]), chi[k] = std::max(chi[k], centroid[order_[i]][k]);
  }
  nodes_[node].lo = lo;
  nodes_[node].hi = hi;
  if (end - begin <= 4) {
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    return;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
  const int mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](int s, int t) { return centroid[s][axis] < centroid[t][axis]; });
  const int left = static_cast<int>(nodes_.size());
  nodes_.push_back({});
  nodes_.push_back({});
  nodes_[node].first = left;
  nodes_[node].count = 0;
  build(left, begin, mid, centroid);
  build(left + 1, mid, end, centroid);
}

double WallSurface::signed_distance(const Vec3& x, Vec3& grad) const {
  double best2 = std::numeric_limits<double>::infinity();
  int best_t = -1;
  WsRegion best_region = WsRegion::Face;
  Vec3 best_c;
  // Depth-first, the nearer child first; a box no nearer than the best triangle so far is skipped.
  std::pair<int, double> stack[128];
  int top = 0;
  stack[top++] = {0, ws_box_distance2(x, nodes_[0].lo, nodes_[0].hi)};
  while (top > 0) {
    const auto [n, d2] = stack[--top];
    if (d2 >= best2) continue;
    const Node& node = nodes_[n];
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const auto& tr = triangles_[order_[i]];
        WsRegion region;
        const Vec3 c = ws_closest_point(x, vertices_[tr[0]], vertices_[tr[1]], vertices_[tr[2]], region);
        const double e2 = dot(x - c, x - c);
        if (e2 < best2) best2 = e2, best_t = order_[i], best_region = region, best_c = c;
      }
      continue;
    }
    const int a = node.first, b = node.first + 1;
    const double da = ws_box_distance2(x, nodes_[a].lo, nodes_[a].hi);
    const double db = ws_box_distance2(x, nodes_[b].lo, nodes_[b].hi);
    if (da <= db) {
      if (db < best2) stack[top++] = {b, db};
      if (da < best2) stack[top++] = {a, da};
    } else {
      if (da < best2) stack[top++] = {a, da};
      if (db < best2) stack[top++] = {b, db};
    }
  }
  Vec3 pseudo;
  switch (best_region) {
    case WsRegion::Face: pseudo = face_normal_[best_t]; break;
    case WsRegion::Vertex0: pseudo = vertex_normal_[triangles_[best_t][0]]; break;
    case WsRegion::Vertex1: pseudo = vertex_normal_[triangles_[best_t][1]]; break;
    case WsRegion::Vertex2: pseudo = vertex_normal_[triangles_[best_t][2]]; break;
    case WsRegion::Edge0: pseudo = edge_normal_[best_t][0]; break;
    case WsRegion::Edge1: pseudo = edge_normal_[best_t][1]; break;
    case WsRegion::Edge2: pseudo = edge_normal_[best_t][2]; break;
  }
  const Vec3 r = x - best_c;
  const double d = std::sqrt(best2), sign = dot(r, pseudo) >= 0 ? 1.0 : -1.0;
  grad = d > 0 ? r * (sign / d) : normalized(pseudo);
  return sign * d;
}

double WallSurface::distance(const Vec3& x) const {
  Vec3 g;
  return signed_distance(x, g);
}

Vec3 WallSurface::normal(const Vec3& x) const {
  Vec3 g;
  signed_distance(x, g);
  return g;
}

namespace {

// The triangles of an STL file as corner coordinates, 9 numbers each.
using WsCorners = std::vector<std::array<double, 9>>;

// ASCII STL: "solid", then per facet "facet normal ...", "outer loop", three "vertex x y z", "endloop", "endfacet".
WsCorners ws_read_stl_ascii(const std::string& text, const std::string& label) {
  WsCorners tris;
  std::istringstream in(text);
  std::string line;
  std::vector<double> corners;
  bool in_facet = false;
  for (long number = 1; std::getline(in, line); ++number) {
    std::istringstream words(line);
    std::string word;
    if (!(words >> word)) continue;
    const auto bad = [&](const std::string& what) {
      throw InputError(label + ": line " + std::to_string(number) + " \"" + echoed(line) + "\": " + what);
    };
    if (word == "facet") {
      if (in_facet) bad("a facet before the previous one's endfacet");
      in_facet = true;
      corners.clear();
    } else if (word == "vertex") {
      if (!in_facet) bad("a vertex outside a facet");
      for (int k = 0; k < 3; ++k) {
        std::string number_text;
        if (!(words >> number_text)) bad("must give three coordinates");
        char* end = nullptr;
        const double value = std::strtod(number_text.c_str(), &end);
        if (end == number_text.c_str() || *end != '\0' || !std::isfinite(value)) bad("a coordinate is not a number");
        corners.push_back(value);
      }
      if (corners.size() > 9) bad("a facet with more than three vertices (only triangles are allowed)");
    } else if (word == "endfacet") {
      if (!in_facet || corners.size() != 9) bad("a facet must have three vertices");
      in_facet = false;
      std::array<double, 9> t;
      std::copy(corners.begin(), corners.end(), t.begin());
      tris.push_back(t);
    } else if (word == "endsolid") {
      if (in_facet) bad("endsolid inside a facet");
      break;
    } else if (word != "solid" && word != "outer" && word != "endloop") {
      bad("expected facet, outer loop, vertex, endloop, endfacet or endsolid");
    }
  }
  if (in_facet) throw InputError(label + ": ends inside a facet (no endfacet)");
  return tris;
}

// Binary STL: an 80-byte header, the triangle count (uint32), then 50 bytes per triangle: normal, three corners
// (float32 each, little-endian) and a 2-byte attribute.
WsCorners ws_read_stl_binary(const std::string& bytes, const std::string& label) {
  if (bytes.size() < 84)
    throw InputError(label + ": has " + std::to_string(bytes.size()) +
                     " bytes, too few for a binary STL (84 at least) and not an ASCII STL (\"solid\" then \"facet\") "
                     "or a Gmsh file ($MeshFormat)");
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  const std::uint64_t count = u32(80), expected = 84 + 50 * count;
  if (bytes.size() != expected)
    throw InputError(label + ": a binary STL of " + std::to_string(count) + " triangles (its count at byte 80) has " +
                     std::to_string(expected) + " bytes, the file " + std::to_string(bytes.size()) +
                     " (truncated, or not an STL file)");
  WsCorners tris(count);
  for (std::uint64_t t = 0; t < count; ++t)
    for (int k = 0; k < 9; ++k) {
      const std::uint32_t bits = u32(84 + 50 * t + 12 + 4 * k);
      tris[t][k] = std::bit_cast<float>(bits);
    }
  return tris;
}

}  // namespace

WallSurface read_wall_surface(const std::filesystem::path& file, double scale, const std::string& name) {
  const std::string label = name + " " + file.string();
  if (!(scale > 0) || !std::isfinite(scale))
    throw InputError(label + ": the scale " + std::to_string(scale) + " must be positive");
  std::ifstream in(file, std::ios::binary);
  std::ostringstream content;
  content << in.rdbuf();
  if (!in || in.bad()) throw InputError(label + ": cannot read the file");
  const std::string bytes = content.str();
  if (bytes.empty()) throw InputError(label + ": the file is empty");
  // The first word, after a UTF-8 byte-order mark and white space, tells Gmsh and ASCII STL from binary STL.
  std::size_t at = bytes.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
  while (at < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[at]))) ++at;
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  if (bytes.compare(at, 11, "$MeshFormat") == 0) {
    Mesh mesh;
    try {
      mesh = read_gmsh(file.string());
    } catch (const InputError& e) {
      throw InputError(name + ": " + e.what());
    }
    // The corners only; mid-side nodes are left out and the vertices renumbered.
    std::vector<int> index(mesh.nodes.size(), -1);
    for (const auto& el : mesh.elements) {
      std::array<int, 3> t{};
      for (int k = 0; k < 3; ++k) {
        int& i = index[el[k]];
        if (i < 0) i = static_cast<int>(vertices.size()), vertices.push_back(scale * mesh.nodes[el[k]]);
        t[k] = i;
      }
      triangles.push_back(t);
    }
    return WallSurface(std::move(vertices), std::move(triangles), label);
  }
  bool ascii = false;
  if (bytes.compare(at, 5, "solid") == 0) {
    const std::size_t eol = bytes.find('\n', at);
    std::size_t next = eol == std::string::npos ? bytes.size() : eol + 1;
    while (next < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[next]))) ++next;
    ascii = bytes.compare(next, 5, "facet") == 0 || bytes.compare(next, 8, "endsolid") == 0;
  }
  const WsCorners corners = ascii ? ws_read_stl_ascii(bytes, label) : ws_read_stl_binary(bytes, label);
  // Vertices merged by exact equality of their coordinates (-0 and 0 alike).
  std::map<std::array<double, 3>, int> index;
  for (std::size_t n = 0; n < corners.size(); ++n) {
    const auto& c = corners[n];
    if (!std::all_of(c.begin(), c.end(), [](double v) { return std::isfinite(v); }))
      throw InputError(label + ": triangle " + std::to_string(n) + " has a coordinate that is not a finite number");
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k) {
      const std::array<double, 3> p{c[3 * k] + 0.0, c[3 * k + 1] + 0.0, c[3 * k + 2] + 0.0};
      const auto [it, added] = index.emplace(p, static_cast<int>(vertices.size()));
      if (added) vertices.push_back(scale * Vec3{p[0], p[1], p[2]});
      t[k] = it->second;
    }
    triangles.push_back(t);
  }
  return WallSurface(std::move(vertices), std::move(triangles), label);
}

std::string point_text(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%g, %g, %g]", v.x, v.y, v.z);
  return buf;
}

}  // namespace immerse
