// Cloth: one simulated instance of a ClothModel — its state, forces, pins and integrator.
//
// It is the DynamicSystem the integrators advance. Pins move linearly over a frame, from the
// targets of the previous frame (pinStart) to the targets set for this one (pinEnd); every stage
// of every integrator sees the pins where they are at that stage's time.
#pragma once

#include "ClothForces.h"
#include "ColliderFaceContacts.h"
#include "ColliderProjection.h"
#include "ColliderResponse.h"
#include "FoldCulling.h"
#include "RigidFit.h"
#include "SelfCollision.h"
#include "StrainLimiting.h"
#include "integrators/Integrator.h"
#include "solver/BlockSparseMatrix.h"
#include "solver/FreeVertexMap.h"
#include "solver/PinnedCoupling.h"
#include "solver/VertexFilter.h"

#include <weft/collision/Aabb.h>
#include <weft/engine/World.h>

#include <memory>
#include <optional>

namespace weft {

/// Stages one frame of one cloth ran and skipped (see the StepStats fields of the same names).
struct ClothStageCounters {
  Index colliderNarrowPhases = 0;
  Index colliderNarrowPhasesSkipped = 0;
  Index selfCollisionPasses = 0;
  Index selfCollisionSkipped = 0;
  Index bendingAssemblies = 0;
  Index dampingJacobians = 0;
  Index bvhNodesRefit = 0;
  Index bvhNodesSkipped = 0;
};

/// Result of advancing one cloth by one frame.
struct ClothFrameReport {
  Index substeps = 0;
  ClothStageCounters stages;
  bool sleeping = false;  ///< the cloth slept through the frame (not stepped)
  bool woke = false;      ///< the cloth was asleep and woke at the start of the frame
  bool teleported = false;  ///< carried with its pins' jump (SolverSettings::pinTeleportDistance)
  SelfCollisionReport selfCollision;  ///< summed over substeps
  Index contacts = 0;  ///< vertices touching colliders at the end of the frame
  Index faceContacts = 0;  ///< faces pushed out of colliders (first pass of each substep)
  IntegratorReport integrator;
  /// Strain-limiter iterations and edges left over the limit, summed over the substeps of the
  /// frame's last attempt.
  StrainLimitReport strainLimit;
  StepStatus status = StepStatus::Ok;
  HealthFailure healthFailure = HealthFailure::None;  ///< why the last failed attempt failed
  Real maxStrain = 0;      ///< Cloth::maxStrain() at the end of the frame
  Real kineticEnergy = 0;  ///< J, Cloth::kineticEnergy() at the end of the frame
};

class Cloth final : public DynamicSystem {
 public:
  /// Validates settings; the error names the field and the fix.
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

  /// Advances by one frame of length frameDt starting at world time t, against colliders whose
  /// motions are given at the frame start (their shapes are posed per substep and left posed at
  /// the end of the last substep).
  /// `plan` overrides substeps and PCG limits where its fields are non-zero (frame budget).
  ClothFrameReport stepFrame(Real t, Real frameDt, std::span<ColliderFrame> colliders = {},
                             const StepPlan& plan = {});
  /// Changes gravity and wind (validated by the caller) and wakes the cloth.
  void setExternalFields(const Vec3& gravity, const Vec3& wind);
  /// Wakes the cloth at the start of its next frame (no effect when awake).
  void wake() { m_wakeRequested = true; }
  bool sleeping() const { return m_sleeping; }
  /// Substeps this cloth takes for a frame of frameDt; `predictedUnstable` is set when an
  /// explicit method would need more than maxSubsteps. In automatic mode also enough that no
  /// pin moves farther than an edge per substep towards the targets set for the frame.
  Index plannedSubsteps(Real frameDt, bool* predictedUnstable = nullptr) const {
    return plannedSubsteps(frameDt, predictedUnstable, teleportMotion());
  }
  /// The same, with the pins' travel measured from their frame-start targets carried by `carry`
  /// (the teleport still to come this frame; nullopt once stepFrame has carried the cloth).
  Index plannedSubsteps(Real frameDt, bool* predictedUnstable,
                        const std::optional<RigidFit>& carry) const;

  /// The rigid motion that carries the cloth in a teleport frame: when every pin moves farther
  /// than SolverSettings::pinTeleportDistance cloth sizes from the frame-start to the set
  /// targets, the best fit of the pins' old targets onto the new ones (RigidFit: rotation and
  /// translation; translation only for one pin; for collinear pins the turn about their line is
  /// chosen with gravity's axis); the same fit when the pins turn rigidly by more than
  /// SolverSettings::pinTeleportAngle; else nullopt (no teleport).
  std::optional<RigidFit> teleportMotion() const;
  /// m, the farthest any pin moves between its frame-start and end targets (0 without pins).
  Real largestPinTravel() const;

  Status setPinTargets(std::span<const Vec3> targets);
  /// N per vertex, added to every evaluation until changed; an empty span removes them.
  Status setExternalForces(std::span<const Vec3> forces);
  const Vec3Array& pinTargets() const { return m_pinEnd; }

  const Vec3Array& positions() const { return m_positions; }
  const Vec3Array& velocities() const { return m_velocities; }
  const Vec3Array& normals();  ///< recomputed on demand after a step
  const ClothModel& model() const { return *m_model; }
  const ClothSettings& settings() const { return m_settings; }

  Status setState(std::span<const Vec3> positions, std::span<const Vec3> velocities);

  /// Everything that decides how this cloth continues (see World::saveState).
  struct SavedState {
    Vec3Array positions, velocities, pinTargets, carried;
    bool sleeping = false, wakeRequested = false;
    Index quietFrames = 0;
    std::uint64_t sleepFingerprint = 0;
    Real potentialEnergy = 0;  // J, what a sleeping cloth reports (m_lastPotential)
    bool jammed = false;       // m_jammed: the next substep is hard (tightCgTolerance)
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
  /// Upper bound (Gershgorin, rest state, pins excluded) of the fastest free mode: ω in rad/s
  /// and its damping rate in 1/s. Used to choose explicit substeps.
  Real stiffestFrequency() const { return m_stiffestFrequency; }
  Real stiffestDampingRate() const { return m_stiffestDampingRate; }
  /// Largest stable explicit step for this cloth (infinity for implicit).
  Real stableStep() const { return m_stableStep; }

  // --- Contact with other cloths (ClothClothCollision, run by World after every cloth has
  // stepped the frame). ---
  /// Positions and velocities at the start of the last frame.
  const Vec3Array& frameStartPositions() const { return m_savedPositions; }
  const Vec3Array& frameStartVelocities() const { return m_savedVelocities; }
  /// 1/m per vertex, 0 for pinned vertices.
  const std::vector<Real>& inverseMasses() const { return m_inverseMasses; }
  /// 1 for pinned vertices.
  const std::vector<char>& pinnedMask() const { return m_pinnedMask; }
  /// The end-of-frame state, for a correction made after the frame (the normals are recomputed).
  Vec3Array& correctablePositions() {
    m_normalsValid = false;
    return m_positions;
  }
  Vec3Array& correctableVelocities() { return m_velocities; }
  /// The strain limiter's settings; null when the cloth has none (limit 0 or infinite).
  const StrainLimitSettings* strainLimitSettings() const {
    return m_strainLimiter ? &m_strainLimitSettings : nullptr;
  }
  /// With a strain limiter: the collider contacts its last substep left (normals and vertices
  /// fixed on two surfaces), which a limiter run after the frame holds as the cloth's own does.
  const ContactHolds& contactHolds() const { return m_contactHolds; }

 private:
  Cloth(std::shared_ptr<const ClothModel> model, const ClothSettings& settings,
        const WorldSettings& world, std::vector<Real> masses, TaskSystem* tasks);
  void estimateStiffestMode();
  // Builds the implicit system's rows (m_freeVertexMap), matrix pattern and pin coupling from the
  // pin set; allocates, so it runs when the pin set is set (creation), never per step.
  void buildSystemRows();
  // Runs `substeps` substeps of the frame; the failed check when the state became non-finite or
  // a vertex too fast (checked every substep), None otherwise.
  HealthFailure runSubsteps(Real t, Real frameDt, Index substeps, std::span<ColliderFrame> colliders,
                   ClothFrameReport& report);
  // The self-contact penalties of m_selfContactPairs at x: forces into f, their stiffness times
  // velocityForProduct into stiffnessTimesVelocity, and the couplings of the solve (h² k JᵀJ)
  // into m_contactCouplings (SolverSettings::selfContactStiffness).
  void addSelfContactTerms(const Vec3Array& x, Real h, Vec3Array& f,
                           const Vec3Array& velocityForProduct, Vec3Array& stiffnessTimesVelocity);
  // One self-collision pass over the substep from m_stepStartPositions; adds to the report.
  void resolveSelfCollision(Real h, std::span<ColliderFrame> colliders, ClothFrameReport& report);
  // After the collision passes: strain limiting with the collider contacts held along their
  // normals, then the collisions again, a few rounds (the limiter is on).
  // Returns the edges the last limiter run left over (`edgesOverLimit`, the first run's, when
  // nothing was over).
  Index limitStrainInContact(Real h, std::span<ColliderFrame> colliders, bool selfCollision,
                             Index edgesOverLimit, ClothFrameReport& report);
  // Keeps faces out of the colliders (ColliderFaceContacts) after a collider pass,
  // and then the vertices out of every collider again; returns the face contacts. The step's
  // first pass passes its step h (s) as `frictionStep`: faces take friction, moving positions by
  // h times its velocity change; later passes pass 0, none (the vertex pass does the same).
  Index resolveFaceContacts(Real frictionStep);
  // Constrains in the solve, along the contact normal, the corners of the faces the last face
  // pass left on a body (its holds), so that the solve does not sink them into it (see
  // constrainContacts). Vertices already constrained keep their constraint.
  void constrainFaceCorners(const Vec3Array& x, const Vec3Array& v, Real h, VertexFilter& filter);
  // Whether this substep's rounds in contact run the joint projection: the setting is on, the
  // substep's first collider pass found vertices or faces in contact and its first self-collision
  // pass self-contacts (counts that skipping stages does not change).
  bool jointProjection() const;
  // One strain-limiter run in contact: joint, with every self-contact of the substep and the
  // collider contacts as constraints (ColliderProjection); otherwise with the collider contacts
  // held along their normals and the self-contacts of very different masses held.
  StrainLimitReport projectInContact(Real h, bool selfCollision, bool joint,
                                     const StrainLimitSettings& settings);
  // After a joint projection: vertices, then faces, out of the colliders, each vertex followed
  // from where the projection left it, the bodies at their end pose.
  void keepOutOfCollidersAfterProjection(std::span<ColliderFrame> colliders);
  // The collider response's keep-out pass over m_nearColliders, without friction, updating the
  // contact holds (the limiter's rounds, and after a face pass).
  void keepVerticesOutOfColliders();
  // The colliders near the substep's start and current positions, into m_nearColliders.
  void selectResponseColliders(std::span<const ColliderFrame> colliders);
  // Colliders whose box comes within the contact distance of `points` go to m_nearColliders;
  // counts both kinds in m_stages.
  void selectNearColliders(std::span<const ColliderFrame> colliders, const Aabb& points,
                           const Aabb* carriedStart);
  // Hash of the colliders that could touch the cloth within the coming frame, and whether any of
  // them moves: what a sleeping cloth watches.
  std::uint64_t colliderFingerprint(std::span<const ColliderFrame> colliders, Real frameDt,
                                    bool* anyMoving) const;
  // After a frame: counts quiet frames and puts the cloth to sleep after enough of them.
  void updateSleep(std::span<const ColliderFrame> colliders, Real frameDt, bool pinsMoved);

  std::shared_ptr<const ClothModel> m_model;
  TaskSystem* m_tasks;
  ClothSettings m_settings;
  ClothForces m_forces;
  BlockSparseMatrix m_matrix;         // rows: m_freeVertexMap
  // Rows of the implicit system: the free vertices (pins removed, SolverSettings::
  // removePinnedVertices) or every vertex; built with the pin set, at creation.
  FreeVertexMap m_freeVertexMap;
  PinnedCoupling m_pinnedCoupling;    // A(free row, pinned vertex), assembled with m_matrix
  // Gauss–Seidel colours: of every vertex, from ClothForces::potentialCoupledPairs() at creation
  // (so zero terms and removed pins leave the solve's order alone), and of m_matrix's rows.
  std::vector<Index> m_vertexColors, m_rowColors;
  // Contacts gathered by vertex, renumbered into the solve's rows when pins are removed.
  VertexFilter m_contactFilter;
  std::vector<Index> m_contactRows;   // rows constrained in the solve's filter last step
  std::unique_ptr<Integrator> m_integrator;

  Vec3Array m_positions, m_velocities, m_normals;
  bool m_normalsValid = false;
  // Frame-start copies for rollback when a frame produces non-finite state.
  Vec3Array m_savedPositions, m_savedVelocities;
  Real m_frameStartPotential = 0;  // J, elastic + gravity at the frame start (first substep)
  // J, the potential the last stepped frame reported (start of its last substep): a sleeping
  // cloth has not moved since, so it reports this rather than nothing.
  Real m_lastPotential = 0;
  Real m_meanEdgeLength = 0;  // m, mean rest length of the mesh edges (pin travel per substep)
  // The end-of-attempt checks (strain, energy jump) against the frame start; see stepFrame().
  // Checks a stepped frame given the strain and kinetic energy at its start and end.
  HealthFailure checkFrameHealth(Real startStrain, Real startKinetic, Real endStrain,
                                 Real endKinetic) const;

  std::vector<Index> m_pinnedSorted;   // pinned vertices, increasing
  std::vector<char> m_pinnedMask;      // 1 for pinned vertices
  ColliderResponse m_colliderResponse;
  std::unique_ptr<SelfCollision> m_selfCollision;  // null when ClothSettings::selfCollision is off
  std::unique_ptr<FoldCulling> m_foldCulling;      // with m_selfCollision
  // Null when ClothMaterial::strainLimit is 0 or infinite (off).
  std::unique_ptr<StrainLimiter> m_strainLimiter;
  StrainLimitSettings m_strainLimitSettings;
  ContactHolds m_contactHolds;                     // with the limiter: this substep's contacts
  std::vector<Real> m_heldInverseMasses;           // 0 also for vertices on two surfaces
  std::vector<SeparationHold> m_heldSeparations;   // self-contacts the limiter holds this round
  // Self-contacts in the implicit solve (SolverSettings::selfContactStiffness): N/m, 0 when off;
  // the pairs at this substep's start (separation = thickness), their couplings of the last
  // linearize(), and whether the last substep's self-collision passes found any contact.
  Real m_selfContactStiffness = 0;
  std::vector<SeparationHold> m_selfContactPairs;
  std::vector<ContactCoupling> m_contactCouplings;
  bool m_selfContactsLastStep = false;
  bool m_skipStages = true;                        // WorldSettings::skipUnneededStages
  std::vector<ColliderFrame> m_nearColliders;      // this pass's colliders near the cloth
  ColliderFaceContacts m_faceContacts;             // faces against the colliders, this pass
  // The joint projection (limitStrainInContact in contact with colliders; ColliderProjection.h):
  // its collider constraints, the self-contacts of every pass of the substep, zero normals
  // (no vertex held along a surface), its limiter settings, the positions it ended at and the
  // near colliders held at their end pose (the collider passes after a projection).
  ColliderProjection m_colliderProjection;
  std::vector<SeparationHold> m_substepSelfHolds;
  Vec3Array m_freeContactNormals;
  StrainLimitSettings m_jointLimitSettings;
  Vec3Array m_projectedPositions;
  std::vector<ColliderFrame> m_stillColliders;
  bool m_keepOutFromProjection = false;  // keepVerticesOutOfColliders: from m_projectedPositions
  bool m_massesNeedSeparations = false;  // masses spread beyond kHeldContactMassRatio
  Index m_colliderContacts = 0;  // vertices and faces the substep's first collider pass met
  Index m_substepSelfContacts = 0;  // self-contacts the substep's first self-collision pass met
  ClothStageCounters m_stages;                     // this frame's
  bool m_sleeping = false, m_wakeRequested = false;
  Index m_quietFrames = 0;
  std::uint64_t m_sleepFingerprint = 0;
  // Contact-aware accuracy (SolverSettings::tightCgTolerance): whether the last self-collision
  // pass was heavy, so the next substep is tightened; carried across frames, and its frame-start
  // value for a retry. m_frameTolerance: this frame's tolerance (the plan's or cgTolerance).
  bool m_jammed = false, m_frameStartJammed = false;
  Real m_frameTolerance = 0;
  std::vector<Real> m_inverseMasses;               // 0 for pinned vertices
  std::span<const ColliderFrame> m_colliders;  // this substep's colliders
  Vec3Array m_stepStartPositions, m_stepStartVelocities;
  // By vertex, m/s: the normal velocity change the solve's contact constraint gave each vertex
  // this substep (receiveContactImpulses), the friction bound of the collider response.
  std::vector<Real> m_solveContactImpulses;
  // Vertices constrainFaceCorners constrained in the last solve (freed before the next one).
  std::vector<Index> m_faceConstrainedCorners;
  std::vector<RigidMotion> m_frameStartMotions;
  std::vector<Index> m_pinSlotOfSorted;  // index into settings.pinnedVertices for each sorted pin
  Vec3Array m_pinStart, m_pinEnd;      // targets at frame start and end, in settings order
  Real m_frameStart = 0, m_frameLength = 1;

  Real m_stiffestFrequency = 0, m_stiffestDampingRate = 0;
  Real m_stableStep = 0;
};

}  // namespace weft
