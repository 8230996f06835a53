// Cloth: one simulated instance of a ClothModel — its state, forces, pins and integrator.
//
// It is the DynamicSystem the integrators advance, and it holds no collision code: the substep
// pipeline (SubstepPipeline.h) gives it the collider contacts its implicit solve constrains and
// writes back the positions and velocities the contact stages corrected. Pins move linearly over
// a frame, from the targets of the previous frame (pinStart) to the targets set for this one
// (pinEnd); every stage of every integrator sees the pins where they are at that stage's time.
#pragma once

#include "ClothForces.h"
#include "RigidFit.h"
#include "contact/ContactDetector.h"
#include "contact/SelfContactPenalty.h"
#include "integrators/Integrator.h"
#include "solver/BlockSparseMatrix.h"
#include "solver/FreeVertexMap.h"
#include "solver/ContactCoupling.h"
#include "solver/PinnedCoupling.h"
#include "solver/VertexFilter.h"

#include <weft/engine/World.h>

#include <array>
#include <memory>
#include <optional>

namespace weft {

/// What a sleeping cloth remembers (StagePlanner decides when it sleeps and wakes).
struct ClothSleep {
  bool sleeping = false;
  bool wakeRequested = false;
  Index quietFrames = 0;
  std::uint64_t fingerprint = 0;  ///< the colliders near it when it fell asleep
};

/// Force evaluations of a cloth since the last takeStageCounts(): whether the stages a scene does
/// not need (bending without stiffness, damping Jacobians without damping) were skipped.
struct ClothStageCounts {
  Index bendingAssemblies = 0;
  Index dampingJacobians = 0;
};

class Cloth final : public DynamicSystem {
 public:
  /// Validates settings (ClothSettingsValidation.h); the error names the field and the fix.
  static Result<std::unique_ptr<Cloth>> create(std::shared_ptr<const ClothModel> model,
                                               const ClothSettings& settings,
                                               const WorldSettings& world, TaskSystem* tasks);

  // DynamicSystem
  Index vertexCount() const override { return m_model->vertexCount(); }
  const std::vector<Real>& masses() const override { return m_forces.masses(); }
  Real computeForces(const Vec3Array& x, const Vec3Array& v, Real t, Vec3Array& f) override;
  Real linearize(const Vec3Array& x, const Vec3Array& v, Real t, Real h, Vec3Array& f,
                 const Vec3Array& velocityForProduct, Vec3Array& stiffnessTimesVelocity) override;
  const BlockSparseMatrix& systemMatrix() const override { return m_matrix; }
  const FreeVertexMap* freeVertexMap() const override { return &m_freeVertexMap; }
  void subtractPrescribedCoupling(const Vec3Array& deltaV, Vec3Array& rows) const override {
    m_pinnedCoupling.subtractProduct(deltaV, rows);
  }
  std::span<const Index> rowColors() const override { return m_rowColors; }
  std::span<const Index> prescribedVertices() const override { return m_pinnedSorted; }
  void applyPrescribedMotion(Real t, Vec3Array& x, Vec3Array& v) const override;
  TaskSystem* taskSystem() override { return m_tasks; }
  void constrainContacts(const Vec3Array& x, const Vec3Array& v, Real h,
                         VertexFilter& filter) override;
  void receiveContactImpulses(std::span<const Real> byRow) override;
  std::span<const ContactCoupling> contactCouplings() const override { return m_contactCouplings; }

  // --- One frame, driven by the substep pipeline. ---
  /// Starts a frame of length frameDt at world time t: carries the cloth with its pins when they
  /// teleport (returns true then) and sets the solver's limits from `plan`.
  bool beginFrame(Real t, Real frameDt, const StepPlan& plan);
  /// One integrator step of length h from time t; the implicit solve holds `constraints` (of
  /// the contact space, this cloth's vertices starting at `firstVertex`). `tight`: solve this
  /// substep to SolverSettings::tightCgTolerance.
  void integrate(Real t, Real h, std::span<const SolveConstraint> constraints, Index firstVertex,
                 bool tight, IntegratorReport& report);
  /// Ends the frame: the pins' start targets become this frame's end targets.
  void endFrame();
  /// The frame-start state (for a retry): positions, velocities and the integrator's warm start.
  void restoreFrameStart();

  /// The force evaluations since the last call; resets them.
  ClothStageCounts takeStageCounts() {
    const ClothStageCounts counts = m_stageCounts;
    m_stageCounts = {};
    return counts;
  }
  /// m/s by vertex: the normal velocity change the last solve's contact constraints gave.
  std::span<const Real> solveContactImpulses() const { return m_solveContactImpulses; }
  /// Stops every vertex (a cloth falling asleep).
  void zeroVelocities() {
    for (Vec3& v : m_velocities) v.setZero();
  }
  /// The self-contact pairs of the last substep (this cloth's vertices), which the next implicit
  /// solve holds as penalties (contact/SelfContactPenalty.h).
  void setSelfContacts(std::span<const SelfContactFeatures> features) {
    m_selfContacts.assign(features.begin(), features.end());
  }
  /// m/s: the normal velocity change the last solve's penalty gave the self-contact pair of
  /// `kind` and (this cloth's) `vertices`; 0 when the solve held no such pair.
  Real selfContactImpulse(ContactKind kind, const std::array<Index, 4>& vertices) const;
  /// Takes the contact stages' corrected state (one entry per vertex).
  void setContactResult(std::span<const Vec3> positions, std::span<const Vec3> velocities);

  /// Changes gravity and wind (validated by the caller) and wakes the cloth.
  void setExternalFields(const Vec3& gravity, const Vec3& wind);
  /// Wakes the cloth at the start of its next frame (no effect when awake).
  void wake() { m_sleep.wakeRequested = true; }
  bool sleeping() const { return m_sleep.sleeping; }
  ClothSleep& sleepState() { return m_sleep; }

  /// Substeps this cloth takes for a frame of frameDt; `predictedUnstable` is set when an
  /// explicit method would need more than maxSubsteps. In automatic mode also enough that no
  /// pin moves farther than SolverSettings::maxPinTravelPerSubstep edges per substep.
  Index plannedSubsteps(Real frameDt, bool* predictedUnstable = nullptr) const {
    return plannedSubsteps(frameDt, predictedUnstable, teleportMotion());
  }
  /// The same, with the pins' travel measured from their frame-start targets carried by `carry`.
  Index plannedSubsteps(Real frameDt, bool* predictedUnstable,
                        const std::optional<RigidFit>& carry) const;
  /// The rigid motion that carries the cloth in a teleport frame (SolverSettings::
  /// pinTeleportDistance, pinTeleportAngle), or nullopt.
  std::optional<RigidFit> teleportMotion() const;
  /// m, the farthest any pin moves between its frame-start and end targets (0 without pins).
  Real largestPinTravel() const;
  /// m, the mean rest length of the mesh edges.
  Real meanEdgeLength() const { return m_meanEdgeLength; }

  Status setPinTargets(std::span<const Vec3> targets);
  /// Refuses targets that stretch an edge between two pinned vertices past what the health check
  /// lets a frame end with (kDivergedStrain): no substeps could keep such a frame.
  Status checkPinnedEdges(std::span<const Vec3> targets) const;
  /// N per vertex, added to every evaluation until changed; an empty span removes them.
  Status setExternalForces(std::span<const Vec3> forces);
  const Vec3Array& pinTargets() const { return m_pinEnd; }

  const Vec3Array& positions() const { return m_positions; }
  const Vec3Array& velocities() const { return m_velocities; }
  const Vec3Array& normals();  ///< recomputed on demand after a step
  const ClothModel& model() const { return *m_model; }
  const ClothSettings& settings() const { return m_settings; }
  const ClothForces& forces() const { return m_forces; }

  Status setState(std::span<const Vec3> positions, std::span<const Vec3> velocities);

  /// Everything that decides how this cloth continues (see World::saveState).
  struct SavedState {
    Vec3Array positions, velocities, pinTargets, carried;
    ClothSleep sleep;
    Real potentialEnergy = 0;  // J, what a sleeping cloth reports
    bool jammed = false;       // the next substep is hard (tightCgTolerance)
    std::vector<SelfContactFeatures> selfContacts;  // the next solve's penalties
  };
  void save(SavedState& out) const;
  /// Restores a save of this cloth (sizes checked by the caller).
  void restore(const SavedState& in);
  /// Largest stretch l / l_rest − 1 over mesh edges (0 when nothing is stretched).
  Real maxStrain() const;
  /// J, Σ ½ m v².
  Real kineticEnergy() const;
  /// m/s, largest vertex speed.
  Real maxSpeed() const;
  /// Largest stable explicit step for this cloth (infinity for implicit).
  Real stableStep() const { return m_stableStep; }
  Real stiffestFrequency() const { return m_stiffestFrequency; }
  Real stiffestDampingRate() const { return m_stiffestDampingRate; }

  /// 1/m per vertex, 0 for pinned vertices.
  const std::vector<Real>& inverseMasses() const { return m_inverseMasses; }
  /// 1 for pinned vertices.
  const std::vector<char>& pinnedMask() const { return m_pinnedMask; }
  /// Positions and velocities at the start of the frame.
  const Vec3Array& frameStartPositions() const { return m_frameStartPositions; }
  const Vec3Array& frameStartVelocities() const { return m_frameStartVelocities; }
  /// s, the current frame's start and length.
  Real frameLength() const { return m_frameLength; }
  /// J, elastic + gravity at the start of the frame's first substep, and of its last.
  Real frameStartPotential() const { return m_frameStartPotential; }
  void setFrameStartPotential(Real joules) { m_frameStartPotential = joules; }
  Real lastPotential() const { return m_lastPotential; }
  void setLastPotential(Real joules) { m_lastPotential = joules; }
  /// Contact-aware accuracy: whether the next substep is hard (many self-contacts).
  bool jammed() const { return m_jammed; }
  void setJammed(bool jammed) { m_jammed = jammed; }

 private:
  Cloth(std::shared_ptr<const ClothModel> model, const ClothSettings& settings,
        const WorldSettings& world, std::vector<Real> masses, TaskSystem* tasks);
  void estimateStiffestMode();
  // Builds the implicit system's rows, matrix pattern and pin coupling from the pin set; runs at
  // creation, never per step.
  void buildSystemRows();
  // The penalties of m_solvePairs at x into m_contactCouplings (SelfContactPenalty.h).
  void addSelfContactTerms(const Vec3Array& x, Real h, const Vec3Array& velocityForProduct);

  std::shared_ptr<const ClothModel> m_model;
  TaskSystem* m_tasks;
  ClothSettings m_settings;
  ClothForces m_forces;
  BlockSparseMatrix m_matrix;       // rows: m_freeVertexMap
  FreeVertexMap m_freeVertexMap;    // the free vertices (pins removed) or every vertex
  PinnedCoupling m_pinnedCoupling;  // A(free row, pinned vertex), assembled with m_matrix
  // Gauss–Seidel colours of every vertex (from the potential couplings, so zero terms and
  // removed pins leave the order alone) and of m_matrix's rows.
  std::vector<Index> m_vertexColors, m_rowColors;
  std::unique_ptr<Integrator> m_integrator;

  Vec3Array m_positions, m_velocities, m_normals;
  bool m_normalsValid = false;
  Vec3Array m_frameStartPositions, m_frameStartVelocities;
  Vec3Array m_frameStartCarried;  // the integrator's warm start at the frame start
  Real m_frameStartPotential = 0;
  Real m_lastPotential = 0;
  Real m_meanEdgeLength = 0;
  std::vector<Index> m_pinnedSorted;   // pinned vertices, increasing
  std::vector<Index> m_pinSlotOfSorted;  // index into settings.pinnedVertices per sorted pin
  std::vector<char> m_pinnedMask;
  struct PinnedEdge {
    std::array<Index, 2> slots;  // into settings.pinnedVertices
    Real restLength;
  };
  std::vector<PinnedEdge> m_pinnedEdges;  // edges whose both ends are pinned
  std::vector<Real> m_inverseMasses;
  Vec3Array m_pinStart, m_pinEnd;      // targets at frame start and end, in settings order
  Real m_frameStart = 0, m_frameLength = 1;
  Real m_frameTolerance = 0;
  bool m_yanked = false;               // this frame's pins make every substep hard
  bool m_jammed = false, m_frameStartJammed = false;
  ClothSleep m_sleep;
  // The solve's contact constraints this substep (contact space ids) and the rows they took.
  std::span<const SolveConstraint> m_constraints;
  Index m_firstVertex = 0;
  std::vector<Index> m_contactRows;
  std::vector<Real> m_solveContactImpulses;  // m/s by vertex
  // Self-contacts in the solve: the features of the last substep's pairs (and at the frame start,
  // for a retry), this substep's pairs at its start, their terms; k in N/m (0: an explicit
  // integrator, which takes no terms).
  std::vector<SelfContactFeatures> m_selfContacts, m_frameStartSelfContacts;
  std::vector<SelfContactPair> m_solvePairs;  // in selfContactBefore order after the solve
  std::vector<ContactCoupling> m_contactCouplings;
  Real m_selfContactStiffness = 0;
  ClothStageCounts m_stageCounts;
  Real m_stiffestFrequency = 0, m_stiffestDampingRate = 0;
  Real m_stableStep = 0;
};

}  // namespace weft
