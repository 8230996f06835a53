// StagePlanner: the one place that decides what a frame runs — which cloths sleep through it,
// and in each substep whether cloth pairs need detecting at all.
//
// Sleep. A cloth sleeps after SleepSettings::frames quiet frames (every free vertex slower than
// the sleep speed and its velocity barely changed over the frame, the residual of M a = f, which
// keeps a cloth released from rest awake), while no collider near it moves; its velocities are
// then zeroed. A sleeping cloth is not integrated: its vertices stay in the contact space as
// immovable obstacles. It wakes when asked (new pins, forces, fields, state), when its pins move,
// when a collider near it moves or the set of colliders near it changes, or when an awake cloth
// touched it in the last frame.
//
// Pairs. A substep needs no pair detection when no cloth can touch itself (FoldCulling proves it
// for a disk-like cloth with no fold that moves less than its margin) and no two cloths that
// collide with each other come within their thickness of each other's motion.
#pragma once

#include "FoldCulling.h"
#include "contact/ColliderFrame.h"
#include "contact/ContactDetector.h"
#include "contact/ContactSpace.h"

#include <memory>
#include <span>
#include <vector>

namespace weft {

class Cloth;

class StagePlanner {
 public:
  /// `skip`: WorldSettings::skipUnneededStages (false: every stage runs, nothing sleeps early).
  explicit StagePlanner(bool skip) : m_skip(skip) {}

  /// Prepares per-cloth tables for the space's cloths (when they change).
  void build(const ContactSpace& space);

  /// Before a frame: whether `cloth` steps it (false: it sleeps through); sets `woke` when it
  /// was asleep and wakes now. `colliders` at the frame start.
  bool steps(Cloth& cloth, std::span<const ColliderFrame> colliders, Real frameDt, bool& woke);
  /// After a frame the cloth stepped: counts quiet frames and puts it to sleep after enough.
  void afterFrame(Cloth& cloth, std::span<const ColliderFrame> colliders, Real frameDt,
                  bool pinsMoved);

  /// Whether the substep startX → x of the space needs pair detection; counts the cloths whose
  /// self pairs were needed and skipped.
  bool pairsNeeded(const ContactSpace& space, std::span<const char> stepping, Index& needed,
                   Index& skipped);

 private:
  bool m_skip;
  std::vector<std::unique_ptr<FoldCulling>> m_folds;  // per cloth with self-collision
  std::vector<Aabb> m_boxes;                          // per cloth: its motion's box
};

}  // namespace weft
