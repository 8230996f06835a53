#include "ObjParser.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

namespace weft {
namespace {

// One face as the file gives it: its corners in polygonCorners[first, first + count).
struct Polygon {
  std::size_t first = 0;
  std::size_t count = 0;
  std::size_t line = 0;
};

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Splits a line into blank-separated tokens.
class Tokens {
 public:
  explicit Tokens(std::string_view line) : m_line(line) {}
  bool next(std::string_view& token) {
    while (m_at < m_line.size() && isBlank(m_line[m_at])) ++m_at;
    if (m_at == m_line.size()) return false;
    const std::size_t start = m_at;
    while (m_at < m_line.size() && !isBlank(m_line[m_at])) ++m_at;
    token = m_line.substr(start, m_at - start);
    return true;
  }

 private:
  std::string_view m_line;
  std::size_t m_at = 0;
};

// A token shortened for a message: a hostile file may put a megabyte on one line.
std::string quoted(std::string_view token) {
  constexpr std::size_t kShown = 40;
  std::string text(1, '\'');
  text.append(token.substr(0, kShown));
  if (token.size() > kShown) text.append("...");
  text.push_back('\'');
  return text;
}

enum class NumberKind { Finite, NotANumber, NonFinite };

// Parses a whole token as a real number.
NumberKind parseCoordinate(std::string_view token, Real& value) {
  std::string_view digits = token;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  const char* end = digits.data() + digits.size();
  const std::from_chars_result parsed = std::from_chars(digits.data(), end, value);
  if (parsed.ptr != end || digits.empty()) return NumberKind::NotANumber;
  if (parsed.ec == std::errc::result_out_of_range) {
    // Overflow ("1e400") is refused; underflow ("1e-400") is a coordinate of 0 for any cloth.
    value = std::strtod(std::string(digits).c_str(), nullptr);
  } else if (parsed.ec != std::errc()) {
    return NumberKind::NotANumber;
  }
  return std::isfinite(value) ? NumberKind::Finite : NumberKind::NonFinite;
}

// Projects polygon corners onto the plane of their Newell normal: 2-D points whose signed area
// has the sign of the polygon's winding about that normal.
std::vector<Vec2> projectPolygon(const std::vector<Index>& corners, const Vec3Array& x,
                                 bool& planar) {
  Vec3 normal = Vec3::Zero();
  const std::size_t n = corners.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& a = x[corners[i]];
    const Vec3& b = x[corners[(i + 1) % n]];
    normal += Vec3((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                   (a.x() - b.x()) * (a.y() + b.y()));
  }
  planar = normal.allFinite() && normal.norm() > 0;
  std::vector<Vec2> points(n);
  if (!planar) return points;
  int drop = 0;
  normal.cwiseAbs().maxCoeff(&drop);
  // The two kept axes in cyclic order after the dropped one keep the winding's sign.
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  const Real sign = normal[drop] > 0 ? 1 : -1;
  for (std::size_t i = 0; i < n; ++i) points[i] = Vec2(x[corners[i]][u], sign * x[corners[i]][v]);
  return points;
}

Real cross2(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}

// Ear clipping (counter-clockwise points): appends the triangles to `out` in the polygon's own
// winding. False when no ear is left (a self-intersecting outline); `out` then holds the ears
// cut so far and `remaining` the corners still to triangulate.
bool clipEars(const std::vector<Vec2>& points, std::vector<std::size_t>& remaining,
              const std::vector<Index>& corners, std::vector<Index>& out) {
  while (remaining.size() > 3) {
    const std::size_t m = remaining.size();
    bool clipped = false;
    for (std::size_t k = 0; k < m && !clipped; ++k) {
      const std::size_t a = remaining[(k + m - 1) % m], b = remaining[k], c = remaining[(k + 1) % m];
      if (!(cross2(points[a], points[b], points[c]) > 0)) continue;  // reflex or flat corner
      bool empty = true;
      for (std::size_t j : remaining) {
        if (j == a || j == b || j == c) continue;
        const Vec2& p = points[j];
        if (cross2(points[a], points[b], p) >= 0 && cross2(points[b], points[c], p) >= 0 &&
            cross2(points[c], points[a], p) >= 0) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      out.insert(out.end(), {corners[a], corners[b], corners[c]});
      remaining.erase(remaining.begin() + std::ptrdiff_t(k));
      clipped = true;
    }
    if (!clipped) return false;
  }
  out.insert(out.end(), {corners[remaining[0]], corners[remaining[1]], corners[remaining[2]]});
  return true;
}

// Splits one polygon into triangles (see the design note in ObjParser.h).
void triangulate(const std::vector<Index>& corners, const Vec3Array& x, std::vector<Index>& out) {
  const std::size_t n = corners.size();
  if (n == 3) {
    out.insert(out.end(), corners.begin(), corners.end());
    return;
  }
  bool planar = false;
  const std::vector<Vec2> points = projectPolygon(corners, x, planar);
  if (n == 4) {
    // The shorter diagonal, unless it leaves the quad (a concave quad): then the other one.
    const bool shorter02 = (x[corners[2]] - x[corners[0]]).squaredNorm() <
                           (x[corners[3]] - x[corners[1]]).squaredNorm();
    const bool inside02 = !planar || (cross2(points[0], points[1], points[2]) > 0 &&
                                      cross2(points[0], points[2], points[3]) > 0);
    const bool inside13 = !planar || (cross2(points[0], points[1], points[3]) > 0 &&
                                      cross2(points[1], points[2], points[3]) > 0);
    if ((shorter02 && inside02) || !inside13) {
      out.insert(out.end(), {corners[0], corners[1], corners[2], corners[0], corners[2], corners[3]});
    } else {
      out.insert(out.end(), {corners[0], corners[1], corners[3], corners[1], corners[2], corners[3]});
    }
    return;
  }
  std::vector<std::size_t> remaining(n);
  for (std::size_t i = 0; i < n; ++i) remaining[i] = i;
  if (planar && n <= kMaxEarClippedCorners && clipEars(points, remaining, corners, out)) return;
  // Fan over what is left.
  for (std::size_t k = 1; k + 1 < remaining.size(); ++k) {
    out.insert(out.end(), {corners[remaining[0]], corners[remaining[k]], corners[remaining[k + 1]]});
  }
}

}  // namespace

Result<TriangleMesh> parseObjText(std::string_view text, std::string_view source) {
  const std::string name(source);
  TriangleMesh mesh;
  std::vector<Polygon> polygons;
  std::vector<Index> polygonCorners;  // resolved to 0-based vertex numbers
  std::size_t lineNumber = 0;
  auto at = [&](std::size_t line) { return name + ", line " + std::to_string(line) + ": "; };

  for (std::size_t position = 0; position < text.size();) {
    std::size_t end = text.find('\n', position);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(position, end - position);
    position = end + 1;
    ++lineNumber;
    if (const std::size_t comment = line.find('#'); comment != std::string_view::npos) {
      line = line.substr(0, comment);
    }
    Tokens tokens(line);
    std::string_view keyword;
    if (!tokens.next(keyword)) continue;

    if (keyword == "v") {
      if (mesh.positions.size() >= std::size_t(kInvalidIndex) - 1) {
        return Error{at(lineNumber) + "more than " + std::to_string(kInvalidIndex - 2) +
                     " vertices, the most a cloth model can index; split the mesh"};
      }
      const std::size_t vertex = mesh.positions.size() + 1;  // as the file counts them
      Vec3 position3;
      for (int k = 0; k < 3; ++k) {
        std::string_view token;
        if (!tokens.next(token)) {
          return Error{at(lineNumber) + "vertex " + std::to_string(vertex) + " has " +
                       std::to_string(k) + " coordinates; write 'v x y z'"};
        }
        switch (parseCoordinate(token, position3[k])) {
          case NumberKind::Finite: break;
          case NumberKind::NotANumber:
            return Error{at(lineNumber) + "coordinate " + quoted(token) + " of vertex " +
                         std::to_string(vertex) + " is not a number; write 'v x y z' in metres"};
          case NumberKind::NonFinite:
            return Error{at(lineNumber) + "coordinate " + quoted(token) + " of vertex " +
                         std::to_string(vertex) +
                         " is not a finite number; every coordinate must be finite (metres)"};
        }
      }
      // Further numbers (w, or a vertex colour) carry nothing for a cloth.
      mesh.positions.push_back(position3);
      continue;
    }
    if (keyword != "f") continue;  // vt, vn, o, g, s, usemtl, mtllib, l, p: nothing for a cloth

    Polygon polygon{polygonCorners.size(), 0, lineNumber};
    std::string_view token;
    while (tokens.next(token)) {
      const std::string_view number = token.substr(0, token.find('/'));
      std::int64_t index = 0;
      const char* end = number.data() + number.size();
      const std::string_view digits = (!number.empty() && number.front() == '+') ? number.substr(1) : number;
      const std::from_chars_result parsed = std::from_chars(digits.data(), end, index);
      auto counted = [&] {
        return "the file has " + std::to_string(mesh.positions.size()) + " vertices before this line";
      };
      if (parsed.ec == std::errc::result_out_of_range) {
        return Error{at(lineNumber) + "vertex index " + quoted(number) +
                     " is too large for any integer; " + counted()};
      }
      if (parsed.ec != std::errc() || parsed.ptr != end || digits.empty()) {
        return Error{at(lineNumber) + "face corner " + quoted(token) +
                     " does not start with a vertex index; write 'f i j k' (or i/t/n)"};
      }
      if (index == 0) {
        return Error{at(lineNumber) + "vertex index 0 is invalid; OBJ counts vertices from 1 "
                                      "(or back from -1 for the last one read)"};
      }
      Index vertex = 0;
      if (index < 0) {
        // Relative: -1 is the last vertex read before this line.
        if (std::uint64_t(-(index + 1)) >= mesh.positions.size()) {
          return Error{at(lineNumber) + "vertex index " + std::to_string(index) +
                       " reaches before the first vertex; " + counted()};
        }
        vertex = Index(std::int64_t(mesh.positions.size()) + index);
      } else {
        if (std::uint64_t(index) >= std::uint64_t(kInvalidIndex)) {
          return Error{at(lineNumber) + "vertex index " + std::to_string(index) +
                       " is beyond any cloth model's vertices; " + counted()};
        }
        vertex = Index(index - 1);  // may name a later vertex: checked against the final count
      }
      polygonCorners.push_back(vertex);
      ++polygon.count;
    }
    if (polygon.count < 3) {
      return Error{at(lineNumber) + "a face needs at least three vertices, this one has " +
                   std::to_string(polygon.count)};
    }
    polygons.push_back(polygon);
  }

  const std::size_t vertexCount = mesh.positions.size();
  for (const Polygon& polygon : polygons) {
    for (std::size_t k = 0; k < polygon.count; ++k) {
      const Index vertex = polygonCorners[polygon.first + k];
      if (vertex >= vertexCount) {
        return Error{at(polygon.line) + "vertex index " + std::to_string(std::uint64_t(vertex) + 1) +
                     " is out of range; the file has " + std::to_string(vertexCount) +
                     " vertices (valid indices 1.." + std::to_string(vertexCount) + ")"};
      }
    }
  }
  if (polygons.empty()) return Error{name + " has no faces; a cloth needs at least one triangle"};

  std::vector<Index> corners;
  for (const Polygon& polygon : polygons) {
    corners.assign(polygonCorners.begin() + std::ptrdiff_t(polygon.first),
                   polygonCorners.begin() + std::ptrdiff_t(polygon.first + polygon.count));
    triangulate(corners, mesh.positions, mesh.indices);
    if (mesh.indices.size() / 3 >= std::size_t(kInvalidIndex) - 1) {
      return Error{at(polygon.line) + "more than " + std::to_string(kInvalidIndex - 2) +
                   " triangles, the most a cloth model can index; split the mesh"};
    }
  }
  return mesh;
}

}  // namespace weft
