// BulletCurtain: see the header. How the script drives Bullet:
//   - Pinned nodes have zero mass (Bullet's way of fixing a node); a pre-tick callback gives them,
//     at the start of every Bullet step, the velocity that lands them on CurtainScene::pinTarget at
//     the end of that step. Bullet moves zero-mass nodes by x += v·dt and leaves them out of the
//     constraint projection, so they follow the rod exactly, as Weft's pins do.
//   - The sphere is a kinematic rigid body without a motion state; the same callback puts it where
//     the script wants it at the end of the step and gives it the matching velocity, which Bullet's
//     node–rigid contacts use for friction and for the contact's velocity.
// Bullet takes `substeps` steps of 1/(60·substeps) s per frame (one stepSimulation call each).
#include "BulletCurtain.h"

#include <weft/scenes/Curtain.h>

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyInternals.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include <cmath>
#include <sstream>

namespace weft {
namespace {

btVector3 toBullet(const Vec3& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }
Vec3 fromBullet(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

}  // namespace

struct BulletCurtain::Bullet {
  btSoftBodyRigidBodyCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
  btSphereShape sphereShape{btScalar(CurtainScene::kSphereRadius)};
  std::unique_ptr<btRigidBody> sphere;
  btSoftBody* cloth = nullptr;  // owned here, deleted after removal from the world

  std::vector<int> pinnedNodes;
  Vec3Array pinRest;
  long stepsTaken = 0;  // Bullet steps so far; the script's clock, kept in double
  int substeps = 1;
  bool selfCollision = false;

  ~Bullet() {
    if (cloth) {
      world.removeSoftBody(cloth);
      delete cloth;
    }
    if (sphere) world.removeRigidBody(sphere.get());
  }

  // Called by Bullet at the start of each of its steps (pre-tick callback).
  void beforeStep(double stepDt) {
    const double endTime = double(++stepsTaken) * CurtainScene::kFrameDt / substeps;
    for (std::size_t k = 0; k < pinnedNodes.size(); ++k) {
      btSoftBody::Node& node = cloth->m_nodes[pinnedNodes[k]];
      const btVector3 target = toBullet(CurtainScene::pinTarget(pinRest[k], endTime));
      node.m_v = (target - node.m_x) / btScalar(stepDt);
    }
    const btVector3 start = sphere->getWorldTransform().getOrigin();
    const btVector3 end = toBullet(CurtainScene::spherePosition(endTime));
    btTransform pose;
    pose.setIdentity();
    pose.setOrigin(end);
    sphere->setInterpolationWorldTransform(sphere->getWorldTransform());
    sphere->setWorldTransform(pose);
    sphere->setLinearVelocity((end - start) / btScalar(stepDt));
    sphere->setInterpolationLinearVelocity((end - start) / btScalar(stepDt));
  }

  static void preTick(btDynamicsWorld* world, btScalar stepDt) {
    static_cast<Bullet*>(world->getWorldUserInfo())->beforeStep(double(stepDt));
  }

  // Called by Bullet after its rigid-body step, after the cloth's predicted motion and before the
  // cloth's constraints are solved: finds the cloth's clusters that touch each other and queues
  // Bullet's contact joints for them, which the cluster solver of this same step resolves. This is
  // the call btSoftBody::defaultCollisionHandler(self) would make if CL_SELF could reach it (see
  // README.md: with CL_SS | CL_SELF set, its switch on flags & SVSmask matches no case).
  void afterRigidStep() {
    if (!selfCollision) return;
    btSoftColliders::CollideCL_SS collider;
    collider.ProcessSoftSoft(cloth, cloth);
  }

  static void postTick(btDynamicsWorld* world, btScalar) {
    static_cast<Bullet*>(world->getWorldUserInfo())->afterRigidStep();
  }
};

BulletCurtain::BulletCurtain() : m_bullet(std::make_unique<Bullet>()) {}
BulletCurtain::~BulletCurtain() = default;

Result<std::unique_ptr<BulletCurtain>> BulletCurtain::create(const BulletCurtainSettings& settings) {
  if (settings.size != 1 && settings.size != 4 && settings.size != 16 && settings.size != 64) {
    return Error{"Bullet curtain size " + std::to_string(settings.size) + " is not offered: choose 1, 4, 16 or 64"};
  }
  if (settings.positionIterations < 1 || settings.substeps < 1) {
    return Error{"Bullet curtain: positionIterations and substeps must be at least 1"};
  }
  if (!(settings.stretchStiffness > 0 && settings.stretchStiffness <= 1) ||
      !(settings.bendingStiffnessPerFrame >= 0 && settings.bendingStiffnessPerFrame < 1)) {
    return Error{"Bullet curtain: stretchStiffness must lie in (0, 1] and bendingStiffnessPerFrame in [0, 1)"};
  }
  if (!(settings.collisionMargin >= 0) || !(settings.sdfVoxelSize > 0) || !(settings.dampingRate >= 0)) {
    return Error{"Bullet curtain: collisionMargin must not be negative, sdfVoxelSize must be positive, dampingRate not negative"};
  }
  std::unique_ptr<BulletCurtain> curtain(new BulletCurtain());
  Bullet& bullet = *curtain->m_bullet;
  bullet.substeps = settings.substeps;
  const double stepDt = CurtainScene::kFrameDt / settings.substeps;

  // World: gravity as Weft's, and a finer signed-distance field than Bullet's 0.25 m default, whose
  // trilinear interpolation would misplace the 0.25 m sphere's surface by centimetres.
  const btVector3 gravity(0, btScalar(-9.81), 0);
  bullet.world.setGravity(gravity);
  btSoftBodyWorldInfo& info = bullet.world.getWorldInfo();
  info.m_gravity = gravity;
  info.m_broadphase = &bullet.broadphase;
  info.m_dispatcher = &bullet.dispatcher;
  info.m_sparsesdf.Initialize();
  info.m_sparsesdf.setDefaultVoxelsz(btScalar(settings.sdfVoxelSize));
  info.m_sparsesdf.Reset();
  bullet.world.setInternalTickCallback(&Bullet::preTick, &bullet, /*isPreTick=*/true);
  bullet.world.setInternalTickCallback(&Bullet::postTick, &bullet, /*isPreTick=*/false);

  // The patch: corners as Weft's grid (x from −1 to 1, y from 0.5 to 2.0), one diagonal per quad.
  const std::array<Index, 2> grid = CurtainScene::gridSize(settings.size);
  const int columns = int(grid[0]), rows = int(grid[1]);
  btSoftBody* cloth = btSoftBodyHelpers::CreatePatch(
      info, btVector3(-1, 0.5, 0), btVector3(1, 0.5, 0), btVector3(-1, 2.0, 0), btVector3(1, 2.0, 0),
      columns, rows, /*fixeds=*/0, /*gendiags=*/true);
  bullet.cloth = cloth;
  for (int i = 0; i < cloth->m_nodes.size(); ++i) curtain->m_restPositions.push_back(fromBullet(cloth->m_nodes[i].m_x));
  for (int f = 0; f < cloth->m_faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) curtain->m_indices.push_back(Index(cloth->m_faces[f].m_n[k] - &cloth->m_nodes[0]));
  }

  // Materials: the mesh links as stiff as Bullet allows; bending links (between nodes two links
  // apart) soft, at a per-iteration stiffness that keeps their per-frame effect fixed.
  cloth->m_materials[0]->m_kLST = btScalar(settings.stretchStiffness);
  btSoftBody::Material* bending = cloth->appendMaterial();
  const int iterations = settings.positionIterations;
  bending->m_kLST = btScalar(1 - std::pow(1 - settings.bendingStiffnessPerFrame, 1.0 / iterations));
  if (settings.bendingStiffnessPerFrame > 0) cloth->generateBendingConstraints(2, bending);
  // Gauss–Seidel in Bullet's link order drifts toward the order; shuffling is Bullet's remedy.
  cloth->randomizeConstraints();

  // Mass: 0.15 kg/m² over 3 m², spread by face area, then the top row fixed (mass 0).
  cloth->setTotalMass(btScalar(0.15 * 3.0), /*fromfaces=*/true);
  for (int column = 0; column < columns; ++column) {
    const int node = (rows - 1) * columns + column;
    cloth->setMass(node, 0);
    bullet.pinnedNodes.push_back(node);
    bullet.pinRest.push_back(curtain->m_restPositions[std::size_t(node)]);
  }

  // Solver and contact settings.
  btSoftBody::Config& config = cloth->m_cfg;
  config.piterations = iterations;
  config.kDP = btScalar(1 - std::exp(-settings.dampingRate * stepDt));
  config.kDF = btScalar(settings.friction);
  config.kCHR = 1;  // rigid contacts fully resolved
  config.kKHR = 1;  // the sphere is kinematic: Bullet's default 0.1 lets it sink into the cloth
  config.collisions = btSoftBody::fCollision::SDF_RS;
  const double gridSpacing = 2.0 / (columns - 1);
  const double margin = settings.collisionMargin > 0 ? settings.collisionMargin : gridSpacing / 5;
  cloth->getCollisionShape()->setMargin(btScalar(margin));

  // The ±5 mm pleats Weft starts with (CurtainSettings::initialWaviness), after the rest lengths
  // were taken from the flat patch.
  constexpr double kWaviness = 0.005, kPleatWavelength = 0.25, kPi = 3.14159265358979323846;
  for (int i = 0; i < cloth->m_nodes.size(); ++i) {
    const Vec3& rest = curtain->m_restPositions[std::size_t(i)];
    const double fade = (2.0 - rest.y()) / 1.5;
    btSoftBody::Node& node = cloth->m_nodes[i];
    node.m_x.setZ(btScalar(kWaviness * fade * std::sin(2 * kPi * (rest.x() + 1) / kPleatWavelength)));
    node.m_q = node.m_x;
  }

  if (settings.selfCollision) {
    // Bullet's btSoftRigidDynamicsWorld keeps a cloth off itself only through clusters: vertex-face
    // handling (VF_SS) skips self pairs, and VF_DD needs the deformable world's solver. One cluster
    // per face, because larger k-means clusters are convex hulls of curved cloth and would collide
    // where the cloth does not.
    config.collisions |= btSoftBody::fCollision::CL_SS;
    config.kSSHR_CL = btScalar(settings.selfContactHardness);
    cloth->generateClusters(0);
    bullet.selfCollision = true;
  }
  bullet.world.addSoftBody(cloth);

  // The sphere: kinematic, never deactivated.
  btTransform pose;
  pose.setIdentity();
  pose.setOrigin(toBullet(CurtainScene::spherePosition(0)));
  btRigidBody::btRigidBodyConstructionInfo sphereInfo(0, nullptr, &bullet.sphereShape);
  sphereInfo.m_startWorldTransform = pose;
  sphereInfo.m_friction = btScalar(settings.friction);
  bullet.sphere = std::make_unique<btRigidBody>(sphereInfo);
  bullet.sphere->setCollisionFlags(bullet.sphere->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  bullet.sphere->setActivationState(DISABLE_DEACTIVATION);
  bullet.world.addRigidBody(bullet.sphere.get());
  return curtain;
}

void BulletCurtain::stepFrame() {
  // Bullet's fixed-step accumulator works in float, where 1/60 is not a whole number of 1/120s, so
  // it would now and then take one step too few or too many. Each call below with maxSubSteps = 0
  // is exactly one Bullet step of the given length.
  const btScalar stepDt = btScalar(CurtainScene::kFrameDt / m_bullet->substeps);
  for (int step = 0; step < m_bullet->substeps; ++step) m_bullet->world.stepSimulation(stepDt, 0);
  // Bullet's demos collect unused signed-distance cells once a frame.
  m_bullet->world.getWorldInfo().m_sparsesdf.GarbageCollect();
}

void BulletCurtain::readPositions(Vec3Array& positions) const {
  const btSoftBody& cloth = *m_bullet->cloth;
  positions.resize(std::size_t(cloth.m_nodes.size()));
  for (int i = 0; i < cloth.m_nodes.size(); ++i) positions[std::size_t(i)] = fromBullet(cloth.m_nodes[i].m_x);
}

void BulletCurtain::readVelocities(Vec3Array& velocities) const {
  const btSoftBody& cloth = *m_bullet->cloth;
  velocities.resize(std::size_t(cloth.m_nodes.size()));
  for (int i = 0; i < cloth.m_nodes.size(); ++i) velocities[std::size_t(i)] = fromBullet(cloth.m_nodes[i].m_v);
}

std::string BulletCurtain::describe() const {
  const btSoftBody& cloth = *m_bullet->cloth;
  std::ostringstream text;
  text << cloth.m_nodes.size() << " nodes, " << cloth.m_links.size() << " links, " << cloth.m_faces.size()
       << " faces, " << cloth.m_clusters.size() << " clusters";
  return text.str();
}

}  // namespace weft
