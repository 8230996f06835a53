// FreeVertexMap: see the design note in the header.
#include <solver/FreeVertexMap.h>

#include <cassert>

namespace weft {

void FreeVertexMap::build(Index vertexCount, std::span<const Index> removed) {
  m_rowOfVertex.assign(vertexCount, Index(0));
  for (Index vertex : removed) {
    assert(vertex < vertexCount && "FreeVertexMap::build: removed vertex out of range");
    if (vertex < vertexCount) m_rowOfVertex[vertex] = kInvalidIndex;
  }
  m_vertexOfRow.clear();
  m_vertexOfRow.reserve(vertexCount);
  for (Index vertex = 0; vertex < vertexCount; ++vertex) {
    if (m_rowOfVertex[vertex] == kInvalidIndex) continue;
    m_rowOfVertex[vertex] = static_cast<Index>(m_vertexOfRow.size());
    m_vertexOfRow.push_back(vertex);
  }
}

void FreeVertexMap::gather(const Vec3Array& vertices, Vec3Array& rows) const {
  for (Index row = 0; row < rowCount(); ++row) rows[row] = vertices[m_vertexOfRow[row]];
}

void FreeVertexMap::scatter(const Vec3Array& rows, Vec3Array& vertices) const {
  for (Index row = 0; row < rowCount(); ++row) vertices[m_vertexOfRow[row]] = rows[row];
}

}  // namespace weft
