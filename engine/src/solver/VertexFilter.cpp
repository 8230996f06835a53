// VertexFilter: setting constraints and applying S. See the design note in the header.
#include <solver/VertexFilter.h>

#include <cassert>
#include <cmath>

namespace weft {

void VertexFilter::resize(Index vertexCount) {
  m_kinds.assign(vertexCount, static_cast<std::uint8_t>(ConstraintKind::Free));
  m_targets.assign(vertexCount, Vec3::Zero());
  m_directions.assign(vertexCount, {Vec3::Zero(), Vec3::Zero()});
  m_constrainedVertexCount = 0;
}

void VertexFilter::setAllFree() {
  // Only the kind and the target define the filter; stale directions of free vertices are unread.
  if (m_constrainedVertexCount == 0) return;
  for (Index vertex = 0; vertex < size(); ++vertex) setFree(vertex);
}

void VertexFilter::setKind(Index vertex, ConstraintKind kind) {
  const bool wasConstrained = m_kinds[vertex] != static_cast<std::uint8_t>(ConstraintKind::Free);
  const bool isConstrained = kind != ConstraintKind::Free;
  m_constrainedVertexCount += static_cast<Index>(isConstrained) - static_cast<Index>(wasConstrained);
  m_kinds[vertex] = static_cast<std::uint8_t>(kind);
}

void VertexFilter::setFree(Index vertex) {
  setKind(vertex, ConstraintKind::Free);
  m_targets[vertex].setZero();
}

void VertexFilter::setFixed(Index vertex, const Vec3& target) {
  setKind(vertex, ConstraintKind::Fixed);
  m_targets[vertex] = target;
}

void VertexFilter::copyConstraint(Index vertex, const VertexFilter& from, Index fromVertex) {
  setKind(vertex, from.kind(fromVertex));
  m_targets[vertex] = from.m_targets[fromVertex];
  m_directions[vertex] = from.m_directions[fromVertex];
}

void VertexFilter::setConstrained(Index vertex, const Vec3& direction, const Vec3& target) {
  const Real length = direction.norm();
  assert(length > 0 && std::isfinite(length) &&
         "VertexFilter::setConstrained: direction must be finite and nonzero (a contact normal)");
  if (!(length > 0) || !std::isfinite(length)) {
    setFree(vertex);
    return;
  }
  const Vec3 p = direction / length;
  setKind(vertex, ConstraintKind::OneDirection);
  m_directions[vertex][0] = p;
  // Keep only the prescribed component: the free one would be filtered away anyway.
  m_targets[vertex] = p * p.dot(target);
}

void VertexFilter::setConstrained(Index vertex, const Vec3& direction0, const Vec3& direction1,
                                  const Vec3& target) {
  setConstrained(vertex, direction0, target);
  if (kind(vertex) != ConstraintKind::OneDirection) return;

  // Gram–Schmidt: q is the part of direction1 orthogonal to p, so S = I − p pᵀ − q qᵀ is a
  // projection (symmetric, idempotent) and the two prescribed components do not fight.
  const Vec3& p = m_directions[vertex][0];
  const Real length1 = direction1.norm();
  const Vec3 orthogonal = direction1 - p * p.dot(direction1);
  const Real orthogonalLength = orthogonal.norm();
  if (!(orthogonalLength > kParallelSine * length1) || !std::isfinite(orthogonalLength)) return;
  const Vec3 q = orthogonal / orthogonalLength;
  setKind(vertex, ConstraintKind::TwoDirections);
  m_directions[vertex][1] = q;
  m_targets[vertex] = p * p.dot(target) + q * q.dot(target);
}

Mat3 VertexFilter::projection(Index vertex) const {
  Mat3 s = Mat3::Identity();
  switch (kind(vertex)) {
    case ConstraintKind::Free:
      break;
    case ConstraintKind::TwoDirections:
      s -= m_directions[vertex][1] * m_directions[vertex][1].transpose();
      [[fallthrough]];
    case ConstraintKind::OneDirection:
      s -= m_directions[vertex][0] * m_directions[vertex][0].transpose();
      break;
    case ConstraintKind::Fixed:
      s.setZero();
      break;
  }
  return s;
}

void VertexFilter::apply(const Vec3Array& in, Vec3Array& out) const {
  applyRange(0, size(), in, out);
}

void VertexFilter::applyRange(Index begin, Index end, const Vec3Array& in, Vec3Array& out) const {
  assert(in.size() == size() && out.size() == size() &&
         "VertexFilter::applyRange: arrays need one entry per vertex; call resize() first");
  for (Index vertex = begin; vertex < end; ++vertex) out[vertex] = filter(vertex, in[vertex]);
}

}  // namespace weft
