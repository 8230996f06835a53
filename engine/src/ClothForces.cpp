#include "ClothForces.h"

#include "forces/BaraffWitkin.h"
#include "forces/ChunkColouring.h"
#include "forces/IsometricBending.h"
#include "forces/SpringCondition.h"
#include "forces/StretchLaw.h"

#include <weft/threading/GrainSizes.h>

#include <algorithm>
#include <cassert>
#include <cstdint>
#include <span>

namespace weft {

struct ClothForces::Pass {
  const Vec3Array& x;
  const Vec3Array& v;
  Vec3Array& f;
  // Jacobian pass only:
  Real h = 0;
  BlockSparseMatrix* matrix = nullptr;
  const Vec3Array* velocityForProduct = nullptr;
  Vec3Array* stiffnessTimesVelocity = nullptr;
  bool damping = true;  // element velocity Jacobians are non-zero
  PinnedCoupling* coupling = nullptr;
  Index couplingBase = kInvalidIndex;

  // The block a precomputed slot names, or null for a row that is not assembled (removed vertex).
  Mat3* blockAt(Index slot) const {
    if (slot < couplingBase) return &matrix->block(slot);
    if (slot == kInvalidIndex || !coupling) return nullptr;
    return &coupling->block(slot - couplingBase);
  }
};

namespace {

template <int N>
Eigen::Matrix<Real, 3 * N, 1> gatherVelocities(const std::array<Index, N>& vertices,
                                                const Vec3Array& v) {
  Eigen::Matrix<Real, 3 * N, 1> local;
  for (int a = 0; a < N; ++a) local.template segment<3>(3 * a) = v[vertices[a]];
  return local;
}

// Sorts the elements into the visiting order of ChunkColouring (one chunk per parallel block) and
// returns the colours' offsets.
template <typename ElementType>
std::vector<Index> colourElements(std::vector<ElementType>& elements, Index vertexCount) {
  using Vertices = decltype(ElementType::vertices);
  std::vector<Vertices> vertices;
  vertices.reserve(elements.size());
  for (const ElementType& element : elements) vertices.push_back(element.vertices);
  ChunkColouring colouring =
      colourChunks(std::span<const Vertices>(vertices), vertexCount, kGrainElements);
  std::vector<ElementType> sorted;
  sorted.reserve(elements.size());
  for (Index e : colouring.order) sorted.push_back(elements[e]);
  elements = std::move(sorted);
  return std::move(colouring.offsets);
}

}  // namespace

ClothForces::ClothForces(const ClothModel& model, const ClothForceSettings& settings,
                         std::vector<Real> masses, TaskSystem* tasks)
    : m_model(&model), m_settings(settings), m_masses(std::move(masses)), m_tasks(tasks),
      m_serialTasks(std::make_unique<TaskSystem>(TaskSystemSettings{1})) {
  auto noSlots = [](auto& slots) { slots.fill(kInvalidIndex); };
  if (settings.model == ForceModel::BaraffWitkin) {
    m_triangles.reserve(model.triangles().size());
    for (const TriangleRest& triangle : model.triangles()) {
      TriangleElement element;
      element.vertices = triangle.vertices;
      element.modelIndex = Index(m_triangles.size());
      noSlots(element.slots);
      element.membrane = makeStretchShearRest(triangle, settings.material.warpRestScale,
                                              settings.material.weftRestScale);
      m_triangles.push_back(element);
    }
    m_bending = settings.material.bendingStiffness != 0 || settings.material.bendingDamping != 0 ||
                !settings.skipZeroTerms;
    m_isometricBending =
        m_bending && settings.material.bendingModel == BendingModel::Isometric;
    if (m_isometricBending) {
      buildIsometricBending();
    } else if (m_bending) {
      m_hinges.reserve(model.hinges().size());
      for (const Hinge& hinge : model.hinges()) {
        Element<4> element{hinge.vertices, {}, Index(m_hinges.size())};
        noSlots(element.slots);
        m_hinges.push_back(element);
      }
    }
  } else {
    const MassSpringMaterial& springs = settings.springs;
    m_springs.reserve(model.springs().size());
    for (const Spring& spring : model.springs()) {
      SpringElement element;
      element.vertices = spring.vertices;
      element.modelIndex = Index(&spring - model.springs().data());
      noSlots(element.slots);
      element.restLength = spring.restLength;
      switch (spring.kind) {
        case SpringKind::Structural:
          element.stiffness = springs.structuralStiffness;
          element.damping = springs.structuralDamping;
          break;
        case SpringKind::Shear:
          element.stiffness = springs.shearStiffness;
          element.damping = springs.shearDamping;
          break;
        case SpringKind::Flexion:
          element.stiffness = springs.flexionStiffness;
          element.damping = springs.flexionDamping;
          break;
      }
      // A spring family switched off costs nothing.
      if (element.stiffness != 0 || element.damping != 0 || !settings.skipZeroTerms) {
        m_springs.push_back(element);
      }
    }
  }
  // Without damping every element velocity Jacobian is exactly +0: leaving it out of the scatter
  // changes no bit (x − (+0) = x, and no entry is ever −0).
  const ClothMaterial& m = settings.material;
  const MassSpringMaterial& k = settings.springs;
  m_damping = !settings.skipZeroTerms ||
              (settings.model == ForceModel::BaraffWitkin
                   ? m.stretchDamping != 0 || m.shearDamping != 0 || (m_bending && m.bendingDamping != 0)
                   : k.structuralDamping != 0 || k.shearDamping != 0 || k.flexionDamping != 0);
  m_triangleColours = colourElements(m_triangles, model.vertexCount());
  m_hingeColours = colourElements(m_hinges, model.vertexCount());
  m_springColours = colourElements(m_springs, model.vertexCount());
}

void ClothForces::buildIsometricBending() {
  const std::vector<BendingStencil>& stencils = m_model->bendingStencils();
  const std::vector<StencilWeight>& weights = m_model->bendingWeights();
  const Index vertexCount = m_model->vertexCount();
  // K̂_ab = Σ_s c_s w_sa w_sb: every product as a triplet, stably sorted by (row, column) and
  // summed in stencil order, so the values do not depend on anything but the model.
  struct Triplet {
    Index row, column;
    Real value;
  };
  std::vector<Triplet> triplets;
  std::vector<Index> useCount(vertexCount + 1, 0);
  for (const BendingStencil& stencil : stencils) {
    for (Index a = 0; a < stencil.weightCount; ++a) {
      const StencilWeight& wa = weights[stencil.firstWeight + a];
      ++useCount[wa.vertex + 1];
      for (Index b = 0; b < stencil.weightCount; ++b) {
        const StencilWeight& wb = weights[stencil.firstWeight + b];
        triplets.push_back({wa.vertex, wb.vertex, wa.weight * wb.weight * stencil.energyWeight});
      }
    }
  }
  std::stable_sort(triplets.begin(), triplets.end(), [](const Triplet& a, const Triplet& b) {
    return a.row != b.row ? a.row < b.row : a.column < b.column;
  });
  m_bendingRowOffsets.assign(vertexCount + 1, 0);
  for (std::size_t k = 0; k < triplets.size(); ++k) {
    if (k > 0 && triplets[k].row == triplets[k - 1].row &&
        triplets[k].column == triplets[k - 1].column) {
      m_bendingEntries.back().value += triplets[k].value;
      continue;
    }
    m_bendingEntries.push_back({triplets[k].column, triplets[k].value, kInvalidIndex});
    ++m_bendingRowOffsets[triplets[k].row + 1];
  }
  for (Index v = 0; v < vertexCount; ++v) m_bendingRowOffsets[v + 1] += m_bendingRowOffsets[v];

  // Transpose of the stencils, for the force f_a = −Σ_v w_va r_v gathered per vertex.
  for (Index v = 0; v < vertexCount; ++v) useCount[v + 1] += useCount[v];
  m_stencilUseOffsets = useCount;
  m_stencilUses.resize(useCount.back());
  std::vector<Index> fill(useCount.begin(), useCount.end() - 1);
  for (Index s = 0; s < Index(stencils.size()); ++s) {
    for (Index a = 0; a < stencils[s].weightCount; ++a) {
      const StencilWeight& w = weights[stencils[s].firstWeight + a];
      m_stencilUses[fill[w.vertex]++] = {s, w.weight};
    }
  }
  m_stencilResiduals.assign(stencils.size(), Vec3::Zero());
}

namespace {

// Every pair of an element's vertices (each once, in element order): the blocks it couples.
void appendAllPairs(std::span<const Index> vertices, std::vector<std::array<Index, 2>>& pairs) {
  for (std::size_t a = 0; a < vertices.size(); ++a)
    for (std::size_t b = a + 1; b < vertices.size(); ++b) pairs.push_back({vertices[a], vertices[b]});
}

}  // namespace

std::vector<std::array<Index, 2>> ClothForces::elementPairs() const {
  std::vector<std::array<Index, 2>> pairs;
  const auto addAll = [&pairs](std::span<const Index> vertices) { appendAllPairs(vertices, pairs); };
  for (const auto& element : m_triangles) addAll(element.vertices);
  for (const auto& element : m_hinges) addAll(element.vertices);
  for (const auto& element : m_springs) addAll(element.vertices);
  return pairs;
}

std::vector<std::array<Index, 2>> ClothForces::coupledPairs() const {
  std::vector<std::array<Index, 2>> pairs = elementPairs();
  for (Index row = 0; row + 1 < Index(m_bendingRowOffsets.size()); ++row) {
    for (Index k = m_bendingRowOffsets[row]; k < m_bendingRowOffsets[row + 1]; ++k) {
      if (m_bendingEntries[k].column > row) pairs.push_back({row, m_bendingEntries[k].column});
    }
  }
  return pairs;
}

std::vector<std::array<Index, 2>> ClothForces::isotropicPairs() const {
  if (!m_isometricBending) return {};
  // Pairs some element holds write full blocks; sorted (smaller, larger) for the lookup.
  std::vector<std::array<Index, 2>> general = elementPairs();
  for (auto& pair : general) {
    if (pair[0] > pair[1]) std::swap(pair[0], pair[1]);
  }
  std::sort(general.begin(), general.end());
  std::vector<std::array<Index, 2>> pairs;
  for (Index row = 0; row + 1 < Index(m_bendingRowOffsets.size()); ++row) {
    for (Index k = m_bendingRowOffsets[row]; k < m_bendingRowOffsets[row + 1]; ++k) {
      const std::array<Index, 2> pair{row, m_bendingEntries[k].column};
      if (pair[1] > row && !std::binary_search(general.begin(), general.end(), pair)) {
        pairs.push_back(pair);
      }
    }
  }
  return pairs;
}

void ClothForces::buildSystem(const FreeVertexMap& map, BlockSparseMatrix& matrix,
                              PinnedCoupling& coupling) {
  const auto toRows = [&map](const std::vector<std::array<Index, 2>>& pairs) {
    std::vector<std::array<Index, 2>> rowPairs;
    rowPairs.reserve(pairs.size());
    for (const auto& [a, b] : pairs) {
      const Index rowA = map.row(a), rowB = map.row(b);
      if (rowA != kInvalidIndex && rowB != kInvalidIndex) rowPairs.push_back({rowA, rowB});
    }
    return rowPairs;
  };
  const std::vector<std::array<Index, 2>> pairs = coupledPairs();
  matrix.build(map.rowCount(), toRows(pairs), toRows(isotropicPairs()));
  coupling.build(map, pairs);
  bindMatrix(matrix, map, coupling);
}

std::vector<std::array<Index, 2>> ClothForces::potentialCoupledPairs() const {
  std::vector<std::array<Index, 2>> pairs;
  const auto addAll = [&pairs](std::span<const Index> vertices) { appendAllPairs(vertices, pairs); };
  const ClothModel& model = *m_model;
  if (m_settings.model == ForceModel::BaraffWitkin) {
    for (const TriangleRest& triangle : model.triangles()) addAll(triangle.vertices);
    if (m_settings.material.bendingModel == BendingModel::Isometric) {
      // K̂ couples every two vertices of a stencil (buildIsometricBending).
      std::vector<Index> stencilVertices;
      for (const BendingStencil& stencil : model.bendingStencils()) {
        stencilVertices.clear();
        for (Index a = 0; a < stencil.weightCount; ++a) {
          stencilVertices.push_back(model.bendingWeights()[stencil.firstWeight + a].vertex);
        }
        addAll(stencilVertices);
      }
    } else {
      for (const Hinge& hinge : model.hinges()) addAll(hinge.vertices);
    }
  } else {
    for (const Spring& spring : model.springs()) addAll(spring.vertices);
  }
  return pairs;
}

void ClothForces::bindMatrix(const BlockSparseMatrix& matrix) {
  FreeVertexMap identity;
  identity.build(Index(m_masses.size()), {});
  bindMatrix(matrix, identity, PinnedCoupling{});
}

void ClothForces::bindMatrix(const BlockSparseMatrix& matrix, const FreeVertexMap& map,
                             const PinnedCoupling& coupling) {
  assert(matrix.blockRows() == map.rowCount() && "bindMatrix: matrix rows must be map.rowCount()");
  m_couplingBase = matrix.blockCount();
  // Slot of block (row vertex, column vertex): matrix, coupling (offset) or none.
  const auto slotOf = [&](Index rowVertex, Index columnVertex) {
    const Index row = map.row(rowVertex);
    if (row == kInvalidIndex) return kInvalidIndex;
    const Index column = map.row(columnVertex);
    if (column != kInvalidIndex) {
      const Index slot = matrix.slot(row, column);
      assert(slot != kInvalidIndex && "matrix built without coupledPairs()");
      return slot;
    }
    const Index slot = coupling.slot(row, columnVertex);
    assert(slot != kInvalidIndex && "PinnedCoupling built without coupledPairs()");
    return slot == kInvalidIndex ? kInvalidIndex : m_couplingBase + slot;
  };
  auto bind = [&](auto& element) {
    const int n = static_cast<int>(element.vertices.size());
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        element.slots[a * n + b] = slotOf(element.vertices[a], element.vertices[b]);
  };
  for (auto& element : m_triangles) bind(element);
  for (auto& element : m_hinges) bind(element);
  for (auto& element : m_springs) bind(element);
  for (Index row = 0; row + 1 < Index(m_bendingRowOffsets.size()); ++row) {
    for (Index k = m_bendingRowOffsets[row]; k < m_bendingRowOffsets[row + 1]; ++k) {
      m_bendingEntries[k].slot = slotOf(row, m_bendingEntries[k].column);
    }
  }
  m_slotBending.assign(m_isometricBending ? matrix.blockCount() : 0, 0);
  for (Index vertex = 0; vertex + 1 < Index(m_bendingRowOffsets.size()); ++vertex) {
    for (Index k = m_bendingRowOffsets[vertex]; k < m_bendingRowOffsets[vertex + 1]; ++k) {
      const BendingEntry& entry = m_bendingEntries[k];
      if (entry.slot < m_couplingBase) m_slotBending[entry.slot] = entry.value;
    }
  }
  m_diagonalSlots.resize(m_masses.size());
  m_rowSlots.resize(m_masses.size());
  for (Index i = 0; i < m_masses.size(); ++i) {
    const Index row = map.row(i);
    m_diagonalSlots[i] = row == kInvalidIndex ? kInvalidIndex : matrix.diagonalSlot(row);
    m_rowSlots[i] = row == kInvalidIndex ? std::array<Index, 2>{0, 0}
                                         : std::array<Index, 2>{matrix.rowBegin(row), matrix.rowEnd(row)};
  }
}

namespace {

// Adds one element's forces, and in a Jacobian pass its blocks −h ∂f/∂v − h² ∂f/∂x and its share
// of (∂f/∂x)·v, into the global arrays.
template <int N, typename PassType, typename ElementType>
void scatter(const ElementType& element, const ElementForces<N>& local, const PassType& pass) {
  for (int a = 0; a < N; ++a) pass.f[element.vertices[a]] += local.force.template segment<3>(3 * a);
  if (!pass.matrix) return;
  for (int a = 0; a < N; ++a) {
    Vec3 product = Vec3::Zero();
    for (int b = 0; b < N; ++b) {
      const Mat3 positionBlock = local.positionJacobian.template block<3, 3>(3 * a, 3 * b);
      if (Mat3* block = pass.blockAt(element.slots[a * N + b])) {
        if (pass.damping) {
          *block -= pass.h * local.velocityJacobian.template block<3, 3>(3 * a, 3 * b) +
                    (pass.h * pass.h) * positionBlock;
        } else {
          *block -= (pass.h * pass.h) * positionBlock;
        }
      }
      product += positionBlock * (*pass.velocityForProduct)[element.vertices[b]];
    }
    (*pass.stiffnessTimesVelocity)[element.vertices[a]] += product;
  }
}

// Adds one triangle's stretchShear() terms: its forces, and in a Jacobian pass its share of
// (∂f/∂x)·u and its nine blocks.
template <typename ElementType, typename PassType>
void scatterStretchShear(const ElementType& element, const StretchShearTerms& terms,
                         const PassType& pass) {
  for (int a = 0; a < 3; ++a) pass.f[element.vertices[a]] += terms.force[a];
  if (!pass.matrix) return;
  for (int a = 0; a < 3; ++a) {
    (*pass.stiffnessTimesVelocity)[element.vertices[a]] += terms.stiffnessTimesVelocity[a];
    for (int b = 0; b < 3; ++b) {
      if (Mat3* block = pass.blockAt(element.slots[3 * a + b])) {
        addStretchShearBlock(terms, element.membrane, a, b, *block);
      }
    }
  }
}

}  // namespace

Real ClothForces::evaluate(const Pass& pass) const {
  const ClothMaterial& material = m_settings.material;
  const StiffnessMode mode = m_settings.stiffnessMode;
  const bool jacobians = pass.matrix != nullptr;
  // The Definite mode keeps C ∇²C only for stretched convex conditions (stretch), so the shear
  // and bending Hessians, by far the costliest part of a kernel, are computed only in Exact mode.
  const bool curvatureOfNonConvex = jacobians && mode == StiffnessMode::Exact;
  const Vec3Array& x = pass.x;
  const Vec3Array& probe = jacobians ? *pass.velocityForProduct : pass.v;  // u of (∂f/∂x)·u
  const std::vector<Real>& vertexAreas = m_model->vertexAreas();
  TaskSystem& tasks = m_tasks ? *m_tasks : *m_serialTasks;
  const auto sum = [](Real a, Real b) { return a + b; };
  Real energy = 0;

  // Isometric bending's stencils: E = D/2 Σ_s c_s |r_s|² with r_s = S_s x − α_s n_s, damping k_d on
  // S_s v alike. Each stencil stores c_s (D r_s + k_d S_s v), gathered per vertex below.
  const Real bendingStiffness = material.bendingStiffness;
  if (m_isometricBending) {
    const Real damping = material.bendingDamping;
    const std::vector<BendingStencil>& stencils = m_model->bendingStencils();
    const std::span<const StencilWeight> weights = m_model->bendingWeights();
    const std::span<const Index> ringTriangles = m_model->bendingTriangles();
    const std::vector<Index>& indices = m_model->indices();
    energy += tasks.parallelReduce(
        Index(stencils.size()), kGrainElements, Real(0),
        [&](Index begin, Index end) {
          Real blockEnergy = 0;
          for (Index s = begin; s < end; ++s) {
            const BendingStencil& stencil = stencils[s];
            // S_s x and S_s v in one sweep over the weights.
            Vec3 residual = Vec3::Zero(), rate = Vec3::Zero();
            for (Index k = stencil.firstWeight, last = k + stencil.weightCount; k < last; ++k) {
              residual += weights[k].weight * x[weights[k].vertex];
              rate += weights[k].weight * pass.v[weights[k].vertex];
            }
            if (stencil.restCurvature != 0) {
              residual -= stencil.restCurvature * stencilNormal(stencil, ringTriangles, indices, x);
            }
            blockEnergy += Real(0.5) * bendingStiffness * stencil.energyWeight * residual.squaredNorm();
            m_stencilResiduals[s] =
                stencil.energyWeight * (bendingStiffness * residual + damping * rate);
          }
          return blockEnergy;
        },
        sum);
  }

  // Per vertex: gravity, linear air drag, external forces and the bending force gathered over the
  // stencils that hold the vertex; in a Jacobian pass the vertex's row is started: its blocks
  // zeroed, M + h·drag on the diagonal, and bending's −h ∂f/∂v − h² ∂f/∂x = (h k_d + h² D) K̂ ⊗ I₃
  // with its share of (∂f/∂x)·u = −D K̂ u. One writer per row, entries in column order.
  const Real bendingScale = pass.h * material.bendingDamping + pass.h * pass.h * bendingStiffness;
  energy += tasks.parallelReduce(
      Index(m_masses.size()), kGrainMatrixRows, Real(0),
      [&](Index begin, Index end) {
        Real blockEnergy = 0;
        for (Index i = begin; i < end; ++i) {
          const Real dragCoefficient = material.airDrag * vertexAreas[i];  // N·s/m
          Vec3 force =
              m_masses[i] * m_settings.gravity - dragCoefficient * (pass.v[i] - m_settings.wind);
          blockEnergy -= m_masses[i] * m_settings.gravity.dot(x[i]);
          if (!m_externalForces.empty()) {
            // A constant force is the gradient of the potential −f·x.
            force += m_externalForces[i];
            blockEnergy -= m_externalForces[i].dot(x[i]);
          }
          if (m_isometricBending) {
            for (Index k = m_stencilUseOffsets[i]; k < m_stencilUseOffsets[i + 1]; ++k) {
              force -= m_stencilUses[k].weight * m_stencilResiduals[m_stencilUses[k].stencil];
            }
          }
          pass.f[i] = force;
          if (!jacobians) continue;
          // Every block of the row written once: bending's (h k_d + h² D) K̂_ij I, or zero.
          for (Index slot = m_rowSlots[i][0]; slot < m_rowSlots[i][1]; ++slot) {
            const Real diagonal = m_isometricBending ? bendingScale * m_slotBending[slot] : Real(0);
            Real* block = pass.matrix->block(slot).data();
            block[0] = diagonal, block[1] = 0, block[2] = 0;
            block[3] = 0, block[4] = diagonal, block[5] = 0;
            block[6] = 0, block[7] = 0, block[8] = diagonal;
          }
          if (Mat3* block = pass.blockAt(m_diagonalSlots[i])) {
            block->diagonal().array() += m_masses[i] + pass.h * dragCoefficient;
          }
          Vec3 product = Vec3::Zero();
          if (m_isometricBending) {
            for (Index k = m_bendingRowOffsets[i]; k < m_bendingRowOffsets[i + 1]; ++k) {
              const BendingEntry& entry = m_bendingEntries[k];
              // Blocks towards removed vertices live in the coupling, zeroed by assemble().
              if (entry.slot >= m_couplingBase) {
                if (Mat3* block = pass.blockAt(entry.slot)) {
                  block->diagonal().array() += bendingScale * entry.value;
                }
              }
              product += entry.value * probe[entry.column];
            }
          }
          (*pass.stiffnessTimesVelocity)[i] = -(bendingStiffness * product);
        }
        return blockEnergy;
      },
      sum);

  // One colour at a time, one chunk per block (forces/ChunkColouring.h): chunks of a colour share
  // no vertex, so their scatters never touch the same entry.
  const auto forEachColour = [&](const std::vector<Index>& colours, auto&& elementRange) {
    for (std::size_t colour = 0; colour + 1 < colours.size(); ++colour) {
      const Index first = colours[colour];
      const Index count = colours[colour + 1] - first;
      // The overflow colour may hold elements that share vertices: one block, one thread.
      const Index grain =
          colour == ChunkColouring::kOverflowColour ? std::max<Index>(count, 1) : kGrainElements;
      energy += tasks.parallelReduce(
          count, grain, Real(0),
          [&](Index begin, Index end) { return elementRange(first + begin, first + end); }, sum);
    }
  };

  // Linear or biphasic stretch (forces/StretchLaw.h).
  const StretchLaw warpLaw = warpStretchLaw(material), weftLaw = weftStretchLaw(material);
  const bool linear = !warpLaw.stiffens() && !weftLaw.stiffens();
  if (linear && (!jacobians || mode == StiffnessMode::Definite)) {
    // Stretch and shear fused (stretchShear): forces need no mode, Definite Jacobians are its own.
    const StretchShearCoefficients coefficients{material.warpStretchStiffness,
                                                material.weftStretchStiffness,
                                                material.shearStiffness, material.stretchDamping,
                                                material.shearDamping};
    forEachColour(m_triangleColours, [&](Index begin, Index end) {
      Real blockEnergy = 0;
      for (Index t = begin; t < end; ++t) {
        const TriangleElement& element = m_triangles[t];
        const std::array<Index, 3>& corner = element.vertices;
        const StretchShearTerms terms = stretchShear(
            {x[corner[0]], x[corner[1]], x[corner[2]]},
            {pass.v[corner[0]], pass.v[corner[1]], pass.v[corner[2]]},
            {probe[corner[0]], probe[corner[1]], probe[corner[2]]}, element.membrane,
            coefficients, pass.h, jacobians);
        blockEnergy += terms.energy;
        scatterStretchShear(element, terms, pass);
      }
      return blockEnergy;
    });
  } else {
    const std::vector<TriangleRest>& triangles = m_model->triangles();
    forEachColour(m_triangleColours, [&](Index begin, Index end) {
      Real blockEnergy = 0;
      ElementForces<3> triangleForces;
      for (Index t = begin; t < end; ++t) {
        const TriangleElement& element = m_triangles[t];
        const TriangleRest& rest = triangles[element.modelIndex];
        const Vec3& x0 = x[element.vertices[0]];
        const Vec3& x1 = x[element.vertices[1]];
        const Vec3& x2 = x[element.vertices[2]];
        const auto velocities = gatherVelocities<3>(element.vertices, pass.v);
        triangleForces.setZero();
        const StretchConditions stretch = stretchConditions(
            x0, x1, x2, rest, material.warpRestScale, material.weftRestScale, jacobians);
        accumulateStretchForces(stretch.warp, warpLaw, rest.area, material.stretchDamping,
                                velocities, mode, jacobians, triangleForces);
        accumulateStretchForces(stretch.weft, weftLaw, rest.area, material.stretchDamping,
                                velocities, mode, jacobians, triangleForces);
        accumulateConditionForces(shearCondition(x0, x1, x2, rest, curvatureOfNonConvex),
                                  material.shearStiffness, material.shearDamping, velocities,
                                  mode, jacobians, triangleForces);
        blockEnergy += triangleForces.energy;
        scatter<3>(element, triangleForces, pass);
      }
      return blockEnergy;
    });
  }

  const std::vector<Hinge>& hinges = m_model->hinges();
  forEachColour(m_hingeColours, [&](Index begin, Index end) {
    Real blockEnergy = 0;
    ElementForces<4> hingeForces;
    for (Index k = begin; k < end; ++k) {
      const Element<4>& element = m_hinges[k];
      const auto& vertices = element.vertices;
      hingeForces.setZero();
      accumulateConditionForces(
          bendCondition(x[vertices[0]], x[vertices[1]], x[vertices[2]], x[vertices[3]],
                        hinges[element.modelIndex], curvatureOfNonConvex),
          material.bendingStiffness, material.bendingDamping,
          gatherVelocities<4>(vertices, pass.v), mode, jacobians, hingeForces);
      blockEnergy += hingeForces.energy;
      scatter<4>(element, hingeForces, pass);
    }
    return blockEnergy;
  });

  forEachColour(m_springColours, [&](Index begin, Index end) {
    Real blockEnergy = 0;
    ElementForces<2> springForces;
    for (Index k = begin; k < end; ++k) {
      const SpringElement& element = m_springs[k];
      springForces.setZero();
      accumulateConditionForces(
          springCondition(x[element.vertices[0]], x[element.vertices[1]], element.restLength,
                          jacobians),
          element.stiffness, element.damping, gatherVelocities<2>(element.vertices, pass.v), mode,
          jacobians, springForces);
      blockEnergy += springForces.energy;
      scatter<2>(element, springForces, pass);
    }
    return blockEnergy;
  });
  return energy;
}

Real ClothForces::computeForces(const Vec3Array& x, const Vec3Array& v, Vec3Array& f) const {
  f.resize(m_masses.size());
  return evaluate(Pass{x, v, f});
}

Real ClothForces::assemble(const Vec3Array& x, const Vec3Array& v, Real h, BlockSparseMatrix& matrix,
                           Vec3Array& f, const Vec3Array& velocityForProduct,
                           Vec3Array& stiffnessTimesVelocity, PinnedCoupling* coupling) const {
  f.resize(m_masses.size());
  stiffnessTimesVelocity.resize(m_masses.size());
  // The per-vertex pass starts every matrix row (evaluate); the coupling blocks, written by the
  // rows next to removed vertices, start from zero here.
  if (coupling) coupling->setZero();
  return evaluate(Pass{x, v, f, h, &matrix, &velocityForProduct, &stiffnessTimesVelocity,
                       m_damping, coupling, m_couplingBase});
}

}  // namespace weft
