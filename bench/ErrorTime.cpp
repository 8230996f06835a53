// Error-vs-time sweep on the curtain (bench/results/error-time-curtain.md).
//
// Design note. Every run is the curtain scene with its script, stepped frame by frame on one
// thread, with one SolverSettings changed (or Bullet's soft body on the same script). Its cost is
// the CPU time of the stepping thread per simulated second: the machine is shared, and thread CPU
// time is what a run costs whatever else the cores do (wall time would rank the neighbours'
// builds). Its error is measured against a reference run every 0.1 s of the script and reported
// per phase of the script (settle, the sphere's push, ..., the rod's gather), never at one
// instant:
//   rms        max over the phase's samples of the RMS vertex distance to the reference
//   statistics four differences between the phase's distributions and the reference's, each
//              pooled over the phase's samples: the mean energy (kinetic + elastic + gravity,
//              / M g L), the 50/90/99/100th percentiles of every edge's strain at every sample,
//              the mean share of vertices near a body (nearBodies) and how often each cell of
//              the front silhouette is covered (weighted Jaccard distance). Distributions, not
//              instants: where two accurate runs part, they still agree on these.
// The vertex distance is divided by the cloth's characteristic length (2.5 m).
//
// The reference must be shown to converge. It is run three times: at its step, at half its step
// (the "check"), and at its step from a start moved by 1 nm. Per phase, the check's distance to
// the reference bounds the reference's own error, and a phase's vertex errors are ranked only
// where they are at least 10× that bound: a smaller error is reported as unresolved (below the
// floor) and ties with every other error below the floor. A phase is chaotic when the 1 nm grows
// to at least a tenth of the errors ranked: there vertex distances measure the chaos, not the
// method. Chaotic phases, and phases whose floor lies above the configurations' errors, are
// ranked by their statistics under the same 10× rule, the floor taken from the larger of the
// statistics' change with the step and with the start. The sensitivity is measured at the
// reference's own step: a coarse step's numerical damping hides the motion that amplifies. The
// references are cached in binary files keyed by everything that defines them, including the
// engine's fingerprint (the state hash after two reference frames).
//
// Bullet's points (bench/peers/BulletCurtain.h) run the same script with Bullet's own settings,
// measured against the same reference samples and statistics: its states' energy is that of the
// curtain's material at Bullet's positions and velocities.
#include "ErrorTime.h"

#include "BenchClock.h"
#include "ClothStatistics.h"

#if WEFT_HAVE_BULLET
#include "peers/BulletCurtain.h"
#endif

#include <weft/scenes/Curtain.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <vector>

namespace weft {
namespace {

using Clock = std::chrono::steady_clock;
constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();
constexpr Index kSampleEveryFrames = 6;  // 0.1 s
constexpr Real kResolution = 10;         // a ranked error is at least this × the reference's
constexpr Real kTimingNoise = 0.1;       // CPU-time differences under 10 % are not a ranking
constexpr Real kPerturbation = 1e-9;     // m, the start's change that measures the sensitivity

using bench::threadCpuSeconds;

// One cloth state at a sample time, with what the statistics need beyond the positions.
struct Sample {
  Index frame = 0;
  Vec3Array positions, velocities;
  Real energy = kNaN;               // J, kinetic + elastic + gravity
  Real contacts = kNaN;             // cloth vertices near a body (nearBodies)
};

// One point of the sweep: a Weft solver setting, or a Bullet setting.
struct SweepConfig {
  std::string method;  // "implicit-euler", "bdf2-newton1", "bullet", ...
  SolverSettings solver;
  bool isDefaults = false;
  bool isBullet = false;
  int bulletIterations = 1, bulletSubsteps = 1;
};

struct PhaseError {
  Real rms = kNaN;         // max over the phase's samples, / L
  Real energy = kNaN;      // |mean E − reference's| / (M g L)
  Real strain = kNaN;      // largest difference of the pooled strain percentiles
  Real contacts = kNaN;    // |mean vertices near a body − reference's| / vertices
  Real silhouette = kNaN;  // coverage distance (weighted Jaccard) of the outlines over the phase

  /// The four statistics, in the order of kStatisticNames.
  std::array<Real, 4> statistics() const { return {energy, strain, contacts, silhouette}; }
};

constexpr const char* kStatisticNames[4] = {"energy", "strain", "contacts", "silhouette"};
constexpr std::size_t kContactsStatistic = 2, kSilhouetteStatistic = 3;  // their indices

struct RunResult {
  SweepConfig config;
  Index substeps = 0;
  StepStatus status = StepStatus::Ok;
  bool stable = true;
  Index framesRun = 0;
  Real cpuPerSimulated = 0;  // CPU s of the stepping thread per simulated s
  Real cgIterationsPerFrame = 0;
  std::vector<PhaseError> phases;
};

struct Phase {
  std::string name;
  Real begin = 0, end = 0;
  std::vector<std::size_t> samples;  // indices into the sample list
};

// Total mechanical energy of a curtain state, from a probe world that evaluates the same forces
// at exactly that state (one tiny step reports the potential energy of the state set).
class EnergyProbe {
 public:
  EnergyProbe(std::shared_ptr<const ClothModel> model, const ClothMaterial& material)
      : m_masses(model->vertexMasses(material.arealDensity)) {
    ClothSettings settings;
    settings.material = material;
    settings.solver.substeps = 1;
    settings.sleep.enabled = false;
    m_cloth = m_world.createCloth(std::move(model), settings).value();
  }

  Real energy(const Vec3Array& positions, const Vec3Array& velocities) {
    if (velocities.empty() || !m_world.setState(m_cloth, positions, velocities).ok()) return kNaN;
    m_world.step(1e-12);  // s: only to evaluate the potential energy at the state just set
    Real kinetic = 0;
    for (std::size_t i = 0; i < velocities.size(); ++i) {
      kinetic += 0.5 * m_masses[i] * velocities[i].squaredNorm();
    }
    return kinetic + m_world.stats().potentialEnergy;
  }

 private:
  World m_world{WorldSettings{.threadCount = 1}};
  ClothId m_cloth;
  std::vector<Real> m_masses;
};

// The cloth's vertices within 2 cm of the sphere's surface or of the floor after `frame`: how much
// cloth the bodies hold, counted the same way for every engine (Weft rests its cloth 3 mm off a
// body, Bullet at its 1 cm collision margin).
Real nearBodies(const Vec3Array& positions, Index frame) {
  constexpr Real kNear = 0.02;  // m
  const Vec3 centre = CurtainScene::spherePosition(Real(frame) * CurtainScene::kFrameDt);
  Index near = 0;
  for (const Vec3& x : positions) {
    near += (x - centre).norm() < CurtainScene::kSphereRadius + kNear || x.y() < kNear;
  }
  return Real(near);
}

// Steps one Weft curtain to the last sample frame, recording samples and CPU time. A non-zero
// `perturbation` (m) moves every free vertex by that much first, in a fixed pattern.
RunResult runCurtain(const SweepConfig& config, const std::vector<Index>& sampleFrames,
                     std::vector<Sample>& samples, EnergyProbe& probe, Real perturbation = 0) {
  RunResult result;
  result.config = config;
  CurtainSettings settings;
  settings.solver = config.solver;
  settings.threadCount = 1;
  Result<CurtainScene> created = CurtainScene::create(settings);
  if (!created.ok()) {
    result.stable = false;
    result.status = StepStatus::InvalidInput;
    return result;
  }
  CurtainScene& scene = created.value();
  World& world = scene.world();
  if (perturbation != 0) {
    const std::span<const Vec3> x = world.positions(scene.cloth()).value();
    Vec3Array moved(x.begin(), x.end());
    for (std::size_t i = 0; i < moved.size(); ++i) {
      moved[i] += perturbation * Vec3(std::sin(1.7 * Real(i)), std::cos(2.3 * Real(i)), std::sin(0.9 * Real(i)));
    }
    (void)world.setState(scene.cloth(), moved, Vec3Array(moved.size(), Vec3::Zero()));
  }
  result.substeps = world.plannedSubsteps(scene.cloth(), CurtainScene::kFrameDt).value();
  double cpuSeconds = 0;
  long long cgIterations = 0;
  std::size_t nextSample = 0;
  samples.clear();
  for (Index frame = 1; frame <= sampleFrames.back(); ++frame) {
    const double start = threadCpuSeconds();
    const StepStatus status = scene.stepFrame();
    cpuSeconds += threadCpuSeconds() - start;
    result.status |= status;
    cgIterations += world.stats().cgIterations;
    result.framesRun = frame;
    // Unstable or rolled back: out of the front whatever follows (and retries make it slow).
    if (hasFlag(status, StepStatus::Unstable) || hasFlag(status, StepStatus::RolledBack)) break;
    if (frame == sampleFrames[nextSample]) {
      Sample sample;
      sample.frame = frame;
      const std::span<const Vec3> x = world.positions(scene.cloth()).value();
      const std::span<const Vec3> v = world.velocities(scene.cloth()).value();
      sample.positions.assign(x.begin(), x.end());
      sample.velocities.assign(v.begin(), v.end());
      sample.energy = probe.energy(sample.positions, sample.velocities);
      sample.contacts = nearBodies(sample.positions, frame);
      samples.push_back(std::move(sample));
      ++nextSample;
    }
  }
  result.stable = !hasFlag(result.status, StepStatus::Unstable) &&
                  !hasFlag(result.status, StepStatus::RolledBack) &&
                  samples.size() == sampleFrames.size();
  const Real simulated = Real(result.framesRun) * CurtainScene::kFrameDt;
  result.cpuPerSimulated = simulated > 0 ? cpuSeconds / simulated : 0;
  result.cgIterationsPerFrame = result.framesRun ? Real(cgIterations) / Real(result.framesRun) : 0;
  return result;
}

#if WEFT_HAVE_BULLET
RunResult runBullet(const SweepConfig& config, const std::vector<Index>& sampleFrames,
                    std::vector<Sample>& samples, EnergyProbe& probe) {
  RunResult result;
  result.config = config;
  result.substeps = config.bulletSubsteps;
  BulletCurtainSettings settings;
  settings.positionIterations = config.bulletIterations;
  settings.substeps = config.bulletSubsteps;
  Result<std::unique_ptr<BulletCurtain>> created = BulletCurtain::create(settings);
  if (!created.ok()) {
    result.stable = false;
    result.status = StepStatus::InvalidInput;
    return result;
  }
  BulletCurtain& bullet = *created.value();
  double cpuSeconds = 0;
  std::size_t nextSample = 0;
  samples.clear();
  for (Index frame = 1; frame <= sampleFrames.back(); ++frame) {
    const double start = threadCpuSeconds();
    bullet.stepFrame();
    cpuSeconds += threadCpuSeconds() - start;
    result.framesRun = frame;
    if (frame == sampleFrames[nextSample]) {
      Sample sample;
      sample.frame = frame;
      bullet.readPositions(sample.positions);
      bullet.readVelocities(sample.velocities);
      bool finite = true;
      for (const Vec3& x : sample.positions) finite = finite && x.allFinite();
      if (!finite) {
        result.stable = false;
        result.status = StepStatus::Unstable;  // Bullet blew up
        break;
      }
      sample.energy = probe.energy(sample.positions, sample.velocities);
      sample.contacts = nearBodies(sample.positions, frame);
      samples.push_back(std::move(sample));
      ++nextSample;
    }
  }
  result.stable = result.stable && samples.size() == sampleFrames.size();
  const Real simulated = Real(result.framesRun) * CurtainScene::kFrameDt;
  result.cpuPerSimulated = simulated > 0 ? cpuSeconds / simulated : 0;
  return result;
}
#endif

// ---- reference cache ------------------------------------------------------------------------
// Binary, native endianness: "WEFTREF2", u32 key length, key bytes, u32 samples, u32 vertices,
// then per sample: u32 frame, f64 energy, f64 contacts, 3n f64 positions, 3n f64 velocities.

constexpr char kCacheMagic[8] = {'W', 'E', 'F', 'T', 'R', 'E', 'F', '2'};

template <typename T>
void writeValue(std::ofstream& file, const T& value) {
  file.write(reinterpret_cast<const char*>(&value), sizeof(T));
}
template <typename T>
bool readValue(std::ifstream& file, T& value) {
  return bool(file.read(reinterpret_cast<char*>(&value), sizeof(T)));
}

bool saveReference(const std::string& path, const std::string& key, const std::vector<Sample>& samples) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) return false;
  file.write(kCacheMagic, sizeof(kCacheMagic));
  writeValue(file, std::uint32_t(key.size()));
  file.write(key.data(), std::streamsize(key.size()));
  writeValue(file, std::uint32_t(samples.size()));
  writeValue(file, std::uint32_t(samples.empty() ? 0 : samples[0].positions.size()));
  for (const Sample& sample : samples) {
    writeValue(file, std::uint32_t(sample.frame));
    writeValue(file, sample.energy);
    writeValue(file, sample.contacts);
    for (const Vec3Array* array : {&sample.positions, &sample.velocities}) {
      for (const Vec3& value : *array) file.write(reinterpret_cast<const char*>(value.data()), 3 * sizeof(Real));
    }
  }
  return bool(file);
}

// Reads the cache; empty when the file is missing, unreadable or made for another key.
std::vector<Sample> loadReference(const std::string& path, const std::string& key, std::string& why) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    why = "no cache file yet";
    return {};
  }
  char magic[sizeof(kCacheMagic)];
  std::uint32_t keyLength = 0, sampleCount = 0, vertexCount = 0;
  if (!file.read(magic, sizeof(magic)) || !std::equal(magic, magic + sizeof(magic), kCacheMagic) ||
      !readValue(file, keyLength) || keyLength > (1u << 16)) {
    why = "not a weft-error-time reference file of this version";
    return {};
  }
  std::string storedKey(keyLength, '\0');
  if (!file.read(storedKey.data(), keyLength) || storedKey != key) {
    why = "made for other reference settings or another engine";
    return {};
  }
  if (!readValue(file, sampleCount) || !readValue(file, vertexCount)) {
    why = "truncated";
    return {};
  }
  std::vector<Sample> samples(sampleCount);
  for (Sample& sample : samples) {
    std::uint32_t frame = 0;
    if (!readValue(file, frame) || !readValue(file, sample.energy) || !readValue(file, sample.contacts)) {
      why = "truncated";
      return {};
    }
    sample.frame = frame;
    for (Vec3Array* array : {&sample.positions, &sample.velocities}) {
      array->resize(vertexCount);
      for (Vec3& value : *array) {
        if (!file.read(reinterpret_cast<char*>(value.data()), 3 * sizeof(Real))) {
          why = "truncated";
          return {};
        }
      }
    }
  }
  return samples;
}

// ---- configurations -------------------------------------------------------------------------

std::string formatTolerance(Real tolerance) {
  std::ostringstream text;
  text << std::setprecision(1) << std::scientific << tolerance;
  return text.str();
}

std::string describeConfig(const RunResult& run) {
  const SweepConfig& config = run.config;
  std::ostringstream text;
  if (config.isBullet) {
    text << "bullet piterations=" << config.bulletIterations << " steps/frame="
         << config.bulletSubsteps;
    return text.str();
  }
  text << config.method << " h=1/" << std::lround(Real(run.substeps) / CurtainScene::kFrameDt);
  if (isImplicit(config.solver.integrator)) {
    text << " tol=" << formatTolerance(config.solver.cgTolerance);
    if (config.isDefaults) {
      text << (config.solver.cgStopping == PcgStopping::VelocityError ? " verr" : " residual");
      if (config.solver.tightCgTolerance > 0) {
        text << " tight=" << formatTolerance(config.solver.tightCgTolerance);
      }
    }
  }
  if (config.solver.substeps == 0) text << " (auto)";
  if (config.isDefaults) text << " [defaults]";
  return text.str();
}

// The grid: the defaults first; backward Euler and BDF2 over steps and tolerances with both
// stopping tests, BDF2 with a Newton iteration, the explicit methods at the substeps their
// stability needs, Bullet at a range of iterations.
std::vector<SweepConfig> sweepConfigs(const ErrorTimeOptions& options) {
  std::vector<Index> substeps;
  std::vector<Real> residualTolerances, velocityTolerances;
  if (options.full) {
    substeps = {1, 2, 4, 8, 16};
    residualTolerances = {1e-1, 1e-2, 1e-3, 1e-6};
    velocityTolerances = {1e-1, 3e-2, 1e-2};
  } else if (options.quick) {
    substeps = {1, 2, 4, 8};
    residualTolerances = {1e-1, 1e-3};
    velocityTolerances = {1e-1, 3e-2};
  } else {
    substeps = {1, 2, 4, 8};
    residualTolerances = {1e-1, 1e-2, 1e-4};
    velocityTolerances = {1e-1, 3e-2, 1e-2};
  }
  std::vector<SweepConfig> configs;
  configs.push_back({"implicit-euler", SolverSettings{}, true});
  for (IntegratorKind kind : {IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2}) {
    for (int newton : {0, 1}) {
      for (Index n : substeps) {
        // Newton iterations cost about twice a step: their finest step is left out.
        if (newton > 0 && n > substeps[substeps.size() - 2]) continue;
        for (PcgStopping stopping : {PcgStopping::VelocityError, PcgStopping::RelativeResidual}) {
          const bool velocity = stopping == PcgStopping::VelocityError;
          for (Real tolerance : velocity ? velocityTolerances : residualTolerances) {
            std::string method = integratorName(kind);
            if (newton > 0) method += "-newton" + std::to_string(newton);
            method += velocity ? "-verr" : "-residual";
            SweepConfig config{method, SolverSettings{}, false};
            config.solver.integrator = kind;
            config.solver.substeps = n;
            config.solver.newtonIterations = newton;
            config.solver.cgTolerance = tolerance;
            config.solver.cgStopping = stopping;
            config.solver.cgMaxIterations = 1000;  // the tolerance, not the cap, ends a solve
            config.solver.tightCgTolerance = 0;     // every substep at cgTolerance: a uniform grid
            configs.push_back(config);
          }
        }
      }
    }
  }
  for (IntegratorKind kind : {IntegratorKind::SymplecticEuler, IntegratorKind::RungeKutta4,
                              IntegratorKind::ExplicitEuler, IntegratorKind::Midpoint}) {
    // The world's automatic substeps (its stability estimate): ~100 per frame on the curtain.
    if (!options.full && kind != IntegratorKind::SymplecticEuler) continue;
    SweepConfig config{integratorName(kind), SolverSettings{}, false};
    config.solver.integrator = kind;
    config.solver.substeps = 0;
    configs.push_back(config);
  }
#if WEFT_HAVE_BULLET
  if (options.bullet) {
    for (const auto& [iterations, steps] :
         {std::pair{1, 1}, std::pair{4, 1}, std::pair{16, 1}, std::pair{64, 1}, std::pair{4, 4},
          std::pair{16, 4}}) {
      if (options.quick && steps > 1 && iterations > 4) continue;
      SweepConfig config{"bullet", SolverSettings{}, false};
      config.isBullet = true;
      config.bulletIterations = iterations;
      config.bulletSubsteps = steps;
      configs.push_back(config);
    }
  }
#endif
  return configs;
}

// ---- errors ---------------------------------------------------------------------------------

// A phase's statistics pooled over its samples (ClothStatistics.h): what two runs share where
// the motion is chaotic.
struct PhaseStatistics {
  Real energy = kNaN;    // J, mean over the samples
  Real contacts = kNaN;  // mean over the samples
  StrainPercentiles strain{};  // of every edge at every sample
  Coverage coverage;
};

struct Comparison {
  const ClothModel* model = nullptr;
  SilhouetteGrid grid;
  Real length = 1;        // m
  Real energyScale = 1;   // J, M g L
  std::vector<PhaseStatistics> reference;  // per phase (computed once)
};

PhaseStatistics phaseStatistics(const std::vector<Sample>& samples, const Phase& phase,
                                const Comparison& comparison) {
  PhaseStatistics statistics;
  std::vector<Real> strains;
  Real energy = 0, contacts = 0;
  for (std::size_t k : phase.samples) {
    const Sample& sample = samples[k];
    energy += sample.energy;  // NaN (Bullet: no velocities) stays NaN
    contacts += sample.contacts;
    appendEdgeStrains(*comparison.model, sample.positions, strains);
    statistics.coverage.add(
        comparison.grid.rasterize(comparison.model->indices(), sample.positions));
  }
  const Real count = Real(phase.samples.size());
  statistics.energy = energy / count;
  statistics.contacts = contacts / count;
  statistics.strain = strainPercentiles(strains);
  statistics.coverage.finish();
  return statistics;
}

Comparison prepareComparison(const ClothModel& model, const ClothMaterial& material,
                             const std::vector<Sample>& reference,
                             const std::vector<Phase>& phases) {
  Comparison comparison;
  comparison.model = &model;
  comparison.length = model.characteristicLength();
  comparison.energyScale = model.totalMass(material.arealDensity) * 9.81 * comparison.length;
  for (const Phase& phase : phases) {
    comparison.reference.push_back(phase.samples.empty()
                                       ? PhaseStatistics{}
                                       : phaseStatistics(reference, phase, comparison));
  }
  return comparison;
}

std::vector<PhaseError> measureErrors(const std::vector<Sample>& samples,
                                      const std::vector<Sample>& reference,
                                      const std::vector<Phase>& phases,
                                      const Comparison& comparison) {
  std::vector<PhaseError> errors(phases.size());
  if (samples.size() != reference.size()) return errors;
  for (std::size_t p = 0; p < phases.size(); ++p) {
    if (phases[p].samples.empty()) continue;
    PhaseError& error = errors[p];
    Real rms = 0;
    for (std::size_t k : phases[p].samples) {
      Real sumSquares = 0;
      for (std::size_t i = 0; i < samples[k].positions.size(); ++i) {
        sumSquares += (samples[k].positions[i] - reference[k].positions[i]).squaredNorm();
      }
      rms = std::max(rms, std::sqrt(sumSquares / Real(samples[k].positions.size())));
    }
    error.rms = rms / comparison.length;
    const PhaseStatistics run = phaseStatistics(samples, phases[p], comparison);
    const PhaseStatistics& truth = comparison.reference[p];
    error.energy = std::abs(run.energy - truth.energy) / comparison.energyScale;
    error.strain = 0;
    for (std::size_t q = 0; q < run.strain.size(); ++q) {
      error.strain = std::max(error.strain, std::abs(run.strain[q] - truth.strain[q]));
    }
    error.contacts =
        std::abs(run.contacts - truth.contacts) / Real(comparison.model->vertexCount());
    error.silhouette = coverageDistance(run.coverage, truth.coverage);
  }
  return errors;
}

// ---- ranking --------------------------------------------------------------------------------

// How one phase is ranked: by vertex distance where the reference resolves it, else by the
// statistics. Each has its floor, kResolution × the reference's own uncertainty in it; the
// statistics, whose uncertainties differ by orders of magnitude, are counted in their floors and
// a run's statistics error is the largest of the four so counted.
struct PhaseVerdict {
  Real referenceRms = kNaN;  // check vs reference, / L
  // Per statistic, the larger of check vs reference and perturbed start vs reference.
  std::array<Real, 4> statisticsUncertainty{kNaN, kNaN, kNaN, kNaN};
  // Per statistic, the smallest difference it can show: one contact, or one covered cell, in
  // one sample of the phase (0 for the continuous energy and strain).
  std::array<Real, 4> statisticsQuantum{0, 0, 0, 0};
  Real sensitivity = kNaN;          // reference started 1 nm away vs reference, rms / L
  Real smallestRms = kNaN;          // smallest vertex error of a Weft configuration
  Real smallestStatistics = kNaN;   // smallest statistics error of one, in floors
  bool byDistance = true;           // ranked by vertex distance (else by statistics)
  bool chaotic = false;

  Real statisticFloor(std::size_t statistic) const {
    return kResolution * std::max(statisticsUncertainty[statistic], statisticsQuantum[statistic]);
  }
  // The largest statistic in units of its floor (NaN when none is finite). A continuous
  // statistic the reference pins down to the bit has no floor: any difference counts, hugely.
  Real statisticsInFloors(const PhaseError& error) const {
    constexpr Real kSmallestFloor = 1e-15;
    Real largest = kNaN;
    const std::array<Real, 4> values = error.statistics();
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (!std::isfinite(values[k])) continue;
      const Real inFloors = values[k] / std::max(statisticFloor(k), kSmallestFloor);
      largest = std::isfinite(largest) ? std::max(largest, inFloors) : inFloors;
    }
    return largest;
  }
  // The ranked error's floor: the distance floor, or 1 for statistics counted in floors.
  Real floor() const { return byDistance ? kResolution * referenceRms : Real(1); }
};

Real rankedError(const RunResult& run, std::size_t phase, const PhaseVerdict& verdict) {
  if (!run.stable || phase >= run.phases.size()) return kNaN;
  const Real error = verdict.byDistance ? run.phases[phase].rms
                                        : verdict.statisticsInFloors(run.phases[phase]);
  if (std::isnan(error)) return kNaN;
  // Below the floor the reference cannot tell errors apart: they tie at the floor.
  return std::max(error, verdict.floor());
}

bool dominates(const RunResult& a, const RunResult& b, std::size_t phase, const PhaseVerdict& verdict) {
  const Real errorA = rankedError(a, phase, verdict), errorB = rankedError(b, phase, verdict);
  if (!std::isfinite(errorA) || !std::isfinite(errorB)) return false;
  return a.cpuPerSimulated <= b.cpuPerSimulated && errorA <= errorB &&
         (a.cpuPerSimulated < b.cpuPerSimulated || errorA < errorB);
}

std::vector<std::size_t> paretoFront(const std::vector<RunResult>& runs, std::size_t phase,
                                     const PhaseVerdict& verdict) {
  std::vector<std::size_t> front;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    if (!std::isfinite(rankedError(runs[k], phase, verdict))) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < runs.size() && !dominated; ++j) {
      dominated = j != k && dominates(runs[j], runs[k], phase, verdict);
    }
    if (!dominated) front.push_back(k);
  }
  std::sort(front.begin(), front.end(), [&](std::size_t a, std::size_t b) {
    return runs[a].cpuPerSimulated < runs[b].cpuPerSimulated;
  });
  return front;
}

std::string formatError(Real error, Real floor) {
  std::ostringstream text;
  if (!std::isfinite(error)) return "n/a";
  text << std::setprecision(3) << error;
  if (error < floor) text << "*";
  return text.str();
}

// ---- output ---------------------------------------------------------------------------------

void writeCsv(const std::string& path, const std::vector<RunResult>& runs,
              const std::vector<Phase>& phases, const std::vector<PhaseVerdict>& verdicts,
              const std::vector<std::vector<std::size_t>>& fronts) {
  std::ofstream file(path);
  file << "configuration,method,integrator,substeps,newton_iterations,cg_stopping,cg_tolerance,"
          "defaults,bullet,status,stable,frames,cpu_s_per_sim_s,cg_iterations_per_frame,phase,"
          "rms_error,energy_error,strain_error,contact_error,silhouette_error,statistics_error,"
          "ranked_by,floor,pareto\n";
  file << std::setprecision(6);
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const RunResult& run = runs[k];
    const SolverSettings& solver = run.config.solver;
    for (std::size_t p = 0; p < phases.size(); ++p) {
      const PhaseError error = p < run.phases.size() ? run.phases[p] : PhaseError{};
      const bool onFront = std::find(fronts[p].begin(), fronts[p].end(), k) != fronts[p].end();
      file << '"' << describeConfig(run) << "\"," << run.config.method << ','
           << (run.config.isBullet ? "bullet" : integratorName(solver.integrator)) << ','
           << run.substeps << ',' << (run.config.isBullet ? 0 : solver.newtonIterations) << ','
           << (run.config.isBullet ? ""
               : solver.cgStopping == PcgStopping::VelocityError ? "velocity-error"
                                                                   : "relative-residual")
           << ',' << (run.config.isBullet ? kNaN : solver.cgTolerance) << ','
           << (run.config.isDefaults ? 1 : 0) << ',' << (run.config.isBullet ? 1 : 0) << ','
           << describe(run.status) << ',' << (run.stable ? 1 : 0) << ',' << run.framesRun << ','
           << run.cpuPerSimulated << ',' << run.cgIterationsPerFrame << ",\"" << phases[p].name
           << "\"," << error.rms << ',' << error.energy << ',' << error.strain << ','
           << error.contacts << ',' << error.silhouette << ','
           << verdicts[p].statisticsInFloors(error) << ','
           << (verdicts[p].byDistance ? "distance" : "statistics") << ',' << verdicts[p].floor()
           << ',' << (onFront ? 1 : 0) << '\n';
    }
  }
}

// Writes the data and a gnuplot script next to the PNG and runs gnuplot: one panel per phase,
// each method a series, the front, the defaults and the reference's floor. False (with a
// message) when gnuplot is missing or fails; the tables and the CSV do not need it.
bool writePlot(const std::string& pngPath, const std::vector<RunResult>& runs,
               const std::vector<Phase>& phases, const std::vector<PhaseVerdict>& verdicts,
               const std::vector<std::vector<std::size_t>>& fronts, const std::string& title,
               std::ostream& out) {
  const std::string dataPath = pngPath + ".dat";
  const std::string scriptPath = pngPath + ".gp";
  std::vector<std::string> methods;
  for (const RunResult& run : runs) {
    if (std::find(methods.begin(), methods.end(), run.config.method) == methods.end()) {
      methods.push_back(run.config.method);
    }
  }
  std::ofstream data(dataPath);
  data << std::setprecision(6);
  // Blocks: per phase, one per method, then the front, then the defaults.
  for (std::size_t p = 0; p < phases.size(); ++p) {
    for (const std::string& method : methods) {
      data << "# " << phases[p].name << ": " << method << "\n";
      for (const RunResult& run : runs) {
        const Real error = rankedError(run, p, verdicts[p]);
        if (run.config.method == method && std::isfinite(error)) {
          data << run.cpuPerSimulated << ' ' << error << '\n';
        }
      }
      data << "\n\n";
    }
    data << "# " << phases[p].name << ": front\n";
    for (std::size_t k : fronts[p]) data << runs[k].cpuPerSimulated << ' ' << rankedError(runs[k], p, verdicts[p]) << '\n';
    data << "\n\n# " << phases[p].name << ": defaults\n";
    for (const RunResult& run : runs) {
      if (run.config.isDefaults && std::isfinite(rankedError(run, p, verdicts[p]))) {
        data << run.cpuPerSimulated << ' ' << rankedError(run, p, verdicts[p]) << '\n';
      }
    }
    data << "\n\n";
  }
  data.close();
  const std::size_t blocksPerPhase = methods.size() + 2;
  const int columns = phases.size() > 4 ? 3 : 2;
  const int rows = int((phases.size() + std::size_t(columns) - 1) / std::size_t(columns));
  std::ofstream script(scriptPath);
  script << "set terminal pngcairo size " << 700 * columns << "," << 520 * rows
         << " noenhanced font ',10'\nset output '" << pngPath << "'\n"
         << "set multiplot layout " << rows << "," << columns << " title '" << title << "'\n"
         << "set logscale xy\nset grid\nset key top right font ',8'\n"
         << "set xlabel 'CPU s per simulated s (1 thread)'\n";
  const char* points[] = {"pt 7", "pt 5", "pt 9", "pt 11", "pt 13", "pt 2", "pt 3", "pt 4",
                          "pt 6", "pt 8", "pt 10", "pt 12"};
  for (std::size_t p = 0; p < phases.size(); ++p) {
    script << "set title '" << phases[p].name << " (" << phases[p].begin << "-" << phases[p].end
           << " s), by " << (verdicts[p].byDistance ? "RMS vertex distance / L" : "shape statistics")
           << (verdicts[p].chaotic ? ", chaotic" : "") << "'\n"
           << "set ylabel '"
           << (verdicts[p].byDistance ? "RMS error / L" : "statistics error (floors)")
           << "'\nplot ";
    for (std::size_t m = 0; m < methods.size(); ++m) {
      script << "'" << dataPath << "' index " << p * blocksPerPhase + m << " with points "
             << points[m % 12] << " ps 1.1 title '" << methods[m] << "', ";
    }
    script << "'" << dataPath << "' index " << p * blocksPerPhase + methods.size()
           << " with steps lw 2 lc rgb 'black' title 'front', '" << dataPath << "' index "
           << p * blocksPerPhase + methods.size() + 1
           << " with points pt 6 ps 3 lw 2 lc rgb 'red' title 'SolverSettings{}', "
           << verdicts[p].floor() << " with lines dt 2 lc rgb 'gray' title 'reference floor (10x)'\n";
  }
  script << "unset multiplot\n";
  script.close();
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    out << "plot: gnuplot is not installed (apt-get install gnuplot-nox); its data and script are "
        << dataPath << " and " << scriptPath << "\n";
    return false;
  }
  const std::string command = "gnuplot '" + scriptPath + "'";
  if (std::system(command.c_str()) != 0) {
    out << "plot: gnuplot failed on " << scriptPath << "\n";
    return false;
  }
  out << "plot: " << pngPath << " (data " << dataPath << ", script " << scriptPath << ")\n";
  return true;
}

std::optional<IntegratorKind> implicitIntegratorFromName(const std::string& name) {
  for (IntegratorKind kind : {IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2}) {
    if (name == integratorName(kind)) return kind;
  }
  return std::nullopt;
}

// A reference of the given substeps, read from the cache or computed (and cached); with a
// `perturbation` (m), the same run started from every vertex moved that much (runCurtain).
bool obtainReference(const ErrorTimeOptions& options, IntegratorKind integrator, Index substeps,
                     Real perturbation, const std::vector<Index>& sampleFrames,
                     const std::string& cacheSuffix, EnergyProbe& probe, Index vertexCount,
                     std::vector<Sample>& samples, std::ostream& out) {
  SweepConfig config{"reference", SolverSettings{}, false};
  config.solver.integrator = integrator;
  config.solver.substeps = substeps;
  config.solver.newtonIterations = options.referenceNewtonIterations;
  config.solver.cgTolerance = options.referenceCgTolerance;
  config.solver.cgStopping = PcgStopping::RelativeResidual;
  config.solver.tightCgTolerance = 0;
  config.solver.cgMaxIterations = 5000;
  std::ostringstream keyText;
  keyText << std::setprecision(17) << "weft-error-time reference v3; curtain x1; vertices "
          << vertexCount << "; " << integratorName(integrator) << " substeps " << substeps
          << " newton " << options.referenceNewtonIterations << " cg "
          << options.referenceCgTolerance << "; perturbed " << perturbation << "; frames";
  for (Index frame : sampleFrames) keyText << ' ' << frame;
  {
    // Engine fingerprint: the state hash after the reference's first two frames.
    CurtainSettings settings;
    settings.solver = config.solver;
    settings.threadCount = 1;
    CurtainScene scene = CurtainScene::create(settings).value();
    for (int frame = 0; frame < 2; ++frame) scene.stepFrame();
    keyText << "; engine fingerprint " << std::hex << scene.world().stateHash() << std::dec;
  }
  const std::string path = options.referenceCache.empty() ? "" : options.referenceCache + cacheSuffix;
  std::string why = "no --reference-cache given";
  if (!path.empty()) samples = loadReference(path, keyText.str(), why);
  const std::string name = std::string(integratorName(integrator)) + " h=1/" +
                           std::to_string(std::lround(Real(substeps) / CurtainScene::kFrameDt)) +
                           (perturbation != 0 ? " from a start moved 1 nm" : "");
  if (!samples.empty()) {
    out << "  " << name << " read from " << path << "\n";
    return true;
  }
  out << "  " << name << " computing (" << why << "), " << options.referenceNewtonIterations
      << " Newton iterations, PCG to " << options.referenceCgTolerance << " ..." << std::flush;
  const Clock::time_point start = Clock::now();
  const RunResult run = runCurtain(config, sampleFrames, samples, probe, perturbation);
  out << " " << std::setprecision(4) << std::chrono::duration<double>(Clock::now() - start).count()
      << " s, " << std::setprecision(4) << run.cgIterationsPerFrame << " CG/frame, status "
      << describe(run.status) << "\n";
  if (!run.stable) {
    out << "weft-error-time: the reference run is not healthy (" << describe(run.status)
        << "); change --reference-substeps\n";
    return false;
  }
  if (!path.empty()) {
    out << "  " << name << (saveReference(path, keyText.str(), samples) ? " cached in " : " could not be written to ")
        << path << "\n";
  }
  return true;
}

}  // namespace

int runErrorTime(const ErrorTimeOptions& options, std::ostream& out) {
  if (options.scene == "drape" || options.scene == "pendulum") return runIntegratorStudy(options, out);
  if (options.scene != "curtain") {
    out << "weft-error-time: scene '" << options.scene
        << "' is unknown; choose curtain, drape or pendulum\n";
    return 2;
  }
  const std::optional<IntegratorKind> referenceIntegrator =
      implicitIntegratorFromName(options.referenceIntegrator);
  if (!referenceIntegrator) {
    out << "weft-error-time: --reference-integrator '" << options.referenceIntegrator
        << "' is not an implicit integrator; choose implicit-euler or bdf2\n";
    return 2;
  }
  for (const std::string& path :
       {options.csvPath, options.plotPath, options.markdownPath, options.referenceCache}) {
    if (path.empty()) continue;
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    std::error_code error;
    if (!folder.empty()) std::filesystem::create_directories(folder, error);
    if (error) {
      out << "weft-error-time: cannot create the folder '" << folder.string() << "': "
          << error.message() << "\n";
      return 2;
    }
  }
  // Samples every 0.1 s: the first 3 s (settle, push, withdraw) quick, 6 s (through the gather)
  // by default, the whole script with --full.
  const Real endTime = options.quick ? 3.0 : options.full ? 10.0 : 6.0;
  std::vector<Index> sampleFrames;
  for (Index frame = kSampleEveryFrames; Real(frame) * CurtainScene::kFrameDt <= endTime + 1e-9;
       frame += kSampleEveryFrames) {
    sampleFrames.push_back(frame);
  }
  std::vector<Phase> phases;
  for (const CurtainPhase& phase : CurtainScene::phases()) {
    if (phase.begin >= endTime - 1e-9) break;
    Phase entry{phase.name, phase.begin, std::min(phase.end, endTime), {}};
    for (std::size_t k = 0; k < sampleFrames.size(); ++k) {
      const Real t = Real(sampleFrames[k]) * CurtainScene::kFrameDt;
      if (t > entry.begin + 1e-9 && t <= entry.end + 1e-9) entry.samples.push_back(k);
    }
    phases.push_back(entry);
  }

  const CurtainScene probeScene = CurtainScene::create().value();
  const std::shared_ptr<const ClothModel> model = probeScene.sharedModel();
  const ClothMaterial material = CurtainSettings{}.material;
  EnergyProbe probe(model, material);
  out << "Weft error-vs-time sweep, curtain x1: " << model->vertexCount() << " vertices, "
      << "characteristic length L = " << model->characteristicLength() << " m; " << sampleFrames.size()
      << " samples every 0.1 s to " << endTime << " s, in " << phases.size() << " phases\n"
      << "Cost: CPU time of the stepping thread per simulated second, one thread (the machine is "
         "shared: thread CPU time, not wall time)\n";

  // The reference, its check at half the step, and the reference again from a start moved by
  // 1 nm: where that grows to the errors ranked, the cloth's own motion (contact decisions,
  // buckling, the free hem beside the pushing sphere) amplifies any difference at the
  // reference's resolution, and vertex distances rank chance. It must be the reference's own
  // run: a coarse step damps the motion that amplifies (backward Euler at 1/60 s keeps the
  // push's 1 nm below 1e-5 of L, the reference's step lets it grow to 1e-3).
  std::vector<Sample> reference, check, perturbed;
  out << "reference\n";
  if (!obtainReference(options, *referenceIntegrator, options.referenceSubsteps, 0, sampleFrames,
                       ".ref", probe, model->vertexCount(), reference, out) ||
      !obtainReference(options, *referenceIntegrator, 2 * options.referenceSubsteps, 0,
                       sampleFrames, ".check", probe, model->vertexCount(), check, out) ||
      !obtainReference(options, *referenceIntegrator, options.referenceSubsteps, kPerturbation,
                       sampleFrames, ".perturbed", probe, model->vertexCount(), perturbed, out)) {
    return 1;
  }
  const Comparison comparison = prepareComparison(*model, material, reference, phases);
  const std::vector<PhaseError> referenceErrors = measureErrors(check, reference, phases, comparison);
  const std::vector<PhaseError> sensitivity =
      measureErrors(perturbed, reference, phases, comparison);

  // The sweep.
  std::vector<SweepConfig> configs = sweepConfigs(options);
  if (!options.only.empty()) {
    std::erase_if(configs, [&](const SweepConfig& config) {
      RunResult run;
      run.config = config;
      run.substeps = config.solver.substeps;
      return !config.isDefaults && describeConfig(run).find(options.only) == std::string::npos;
    });
  }
  out << "sweep: " << configs.size() << " runs\n";
  std::vector<RunResult> runs;
  std::vector<Sample> samples;
  const auto run = [&](const SweepConfig& config, std::vector<Sample>& into) {
#if WEFT_HAVE_BULLET
    if (config.isBullet) return runBullet(config, sampleFrames, into, probe);
#endif
    return runCurtain(config, sampleFrames, into, probe);
  };
  for (const SweepConfig& config : configs) {
    RunResult result = run(config, samples);
    result.phases = measureErrors(samples, reference, phases, comparison);
    if (options.progress) {
      out << "  " << std::left << std::setw(58) << describeConfig(result) << std::right << " cpu "
          << std::setw(7) << std::setprecision(3) << result.cpuPerSimulated << " s/s  rms";
      for (const PhaseError& error : result.phases) {
        out << ' ' << std::setw(9) << std::setprecision(3) << error.rms;
      }
      out << "  " << describe(result.status) << "\n" << std::flush;
    }
    runs.push_back(std::move(result));
  }
  // Repeats only re-time (the same settings give the same bits), in rounds over the whole grid:
  // the machine's speed drifts over minutes, and a configuration's repeats run back to back
  // would share one slow spell. Each keeps its least CPU time.
  for (int round = 1; round < options.repeats; ++round) {
    if (options.progress) {
      out << "timing round " << round + 1 << " of " << options.repeats << "\n" << std::flush;
    }
    for (RunResult& result : runs) {
      if (!result.stable) continue;
      std::vector<Sample> again;
      result.cpuPerSimulated =
          std::min(result.cpuPerSimulated, run(result.config, again).cpuPerSimulated);
    }
  }

  // Per phase: what the reference resolves, and how the phase is ranked.
  std::vector<PhaseVerdict> verdicts(phases.size());
  for (std::size_t p = 0; p < phases.size(); ++p) {
    PhaseVerdict& verdict = verdicts[p];
    verdict.referenceRms = referenceErrors[p].rms;
    verdict.sensitivity = sensitivity[p].rms;
    // The statistics' own uncertainty: the larger of their change with the step and with the
    // start (in a chaotic phase, the spread of a finite sample of the motion).
    for (std::size_t k = 0; k < verdict.statisticsUncertainty.size(); ++k) {
      verdict.statisticsUncertainty[k] =
          std::max(referenceErrors[p].statistics()[k], sensitivity[p].statistics()[k]);
    }
    const Real samplesInPhase = Real(phases[p].samples.size());
    const Real coveredCells = Real(comparison.reference[p].coverage.coveredCells);
    verdict.statisticsQuantum[kContactsStatistic] =
        1 / (Real(model->vertexCount()) * samplesInPhase);
    verdict.statisticsQuantum[kSilhouetteStatistic] = coveredCells > 0 ? 1 / coveredCells : 0;
    for (const RunResult& run : runs) {
      if (!run.stable || run.config.isBullet || p >= run.phases.size()) continue;
      const Real rms = run.phases[p].rms, statistics = verdict.statisticsInFloors(run.phases[p]);
      if (std::isfinite(rms)) verdict.smallestRms = std::isfinite(verdict.smallestRms) ? std::min(verdict.smallestRms, rms) : rms;
      if (std::isfinite(statistics)) {
        verdict.smallestStatistics = std::isfinite(verdict.smallestStatistics)
                                         ? std::min(verdict.smallestStatistics, statistics)
                                         : statistics;
      }
    }
    // Chaotic: a 1 nm change grows to a tenth of the smallest error ranked.
    verdict.chaotic = verdict.sensitivity >= 0.1 * verdict.smallestRms;
    // By distance unless the reference's floor lies above the median configuration's error or
    // the phase is chaotic (then vertex distances rank chance).
    std::vector<Real> errors;
    for (const RunResult& run : runs) {
      if (run.stable && !run.config.isBullet && p < run.phases.size() && std::isfinite(run.phases[p].rms)) {
        errors.push_back(run.phases[p].rms);
      }
    }
    std::sort(errors.begin(), errors.end());
    const Real median = errors.empty() ? kNaN : errors[errors.size() / 2];
    verdict.byDistance = !verdict.chaotic && kResolution * verdict.referenceRms <= median;
  }
  std::vector<std::vector<std::size_t>> fronts;
  for (std::size_t p = 0; p < phases.size(); ++p) fronts.push_back(paretoFront(runs, p, verdicts[p]));

  // The reference's convergence, per phase.
  std::ostringstream tables;
  tables << "\nReference: " << options.referenceIntegrator << " at h = 1/"
         << std::lround(Real(options.referenceSubsteps) / CurtainScene::kFrameDt) << " s, "
         << options.referenceNewtonIterations << " Newton iterations, PCG residual "
         << options.referenceCgTolerance << "; check: the same at h/2; sensitivity: the "
            "reference from a start moved 1 nm.\n"
         << "A phase is ranked by vertex distance where the check's distance to the reference (its "
            "floor x" << kResolution << ") lies below the errors ranked and the 1 nm change "
            "does not grow to a tenth of them; otherwise by its statistics pooled over the "
            "phase, each in units of its floor, x" << kResolution << " the larger of its change "
            "with the step and with the start. Errors below the floor tie there (marked *).\n\n";
  tables << "| phase | s | reference vs check: RMS / L | 1 nm start grows to: RMS / L | "
            "smallest Weft RMS / L | uncertainty: energy | strain | contacts | silhouette | "
            "smallest Weft statistics (floors) | ranked by |\n"
         << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
  for (std::size_t p = 0; p < phases.size(); ++p) {
    const PhaseVerdict& verdict = verdicts[p];
    tables << "| " << phases[p].name << " | " << phases[p].begin << "-" << phases[p].end << " | "
           << std::setprecision(3) << verdict.referenceRms << " | " << verdict.sensitivity << " | "
           << verdict.smallestRms << " | ";
    for (Real uncertainty : verdict.statisticsUncertainty) tables << uncertainty << " | ";
    tables << verdict.smallestStatistics << " | "
           << (verdict.byDistance ? "vertex distance"
                                  : std::string("statistics") + (verdict.chaotic ? " (chaotic)" : " (reference unresolved)"))
           << " |\n";
  }

  // The fronts, per phase.
  for (std::size_t p = 0; p < phases.size(); ++p) {
    const PhaseVerdict& verdict = verdicts[p];
    tables << "\n### " << phases[p].name << " (" << phases[p].begin << "-" << phases[p].end
           << " s): Pareto front by "
           << (verdict.byDistance ? "RMS vertex distance / L" : "shape statistics, in floors")
           << "; floors: distance " << std::setprecision(3) << kResolution * verdict.referenceRms;
    for (std::size_t s = 0; s < 4; ++s) {
      tables << ", " << kStatisticNames[s] << ' ' << verdict.statisticFloor(s);
    }
    tables << "\n\n"
           << "| configuration | CPU s per sim s | CG per frame | RMS / L | energy | strain | "
              "contacts | silhouette | statistics (floors) |\n"
           << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (std::size_t k : fronts[p]) {
      const RunResult& run = runs[k];
      const PhaseError& error = run.phases[p];
      tables << "| " << describeConfig(run) << " | " << std::setprecision(3) << run.cpuPerSimulated
             << " | " << std::setprecision(4) << run.cgIterationsPerFrame << " | "
             << formatError(error.rms, kResolution * verdict.referenceRms) << " | ";
      const std::array<Real, 4> values = error.statistics();
      for (std::size_t s = 0; s < 4; ++s) {
        tables << formatError(values[s], verdict.statisticFloor(s)) << " | ";
      }
      tables << formatError(verdict.statisticsInFloors(error), 1) << " |\n";
    }
  }

  // Where the defaults sit, per phase.
  int status = 0;
  tables << "\n### Where SolverSettings{} sits\n\n";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    if (!runs[k].config.isDefaults) continue;
    const RunResult& defaults = runs[k];
    tables << describeConfig(defaults) << ": " << std::setprecision(3) << defaults.cpuPerSimulated
           << " CPU s per simulated s, " << std::setprecision(4) << defaults.cgIterationsPerFrame
           << " CG per frame, status " << describe(defaults.status) << "\n\n";
    for (std::size_t p = 0; p < phases.size(); ++p) {
      const bool onFront = std::find(fronts[p].begin(), fronts[p].end(), k) != fronts[p].end();
      tables << "- " << phases[p].name << ": ";
      if (!defaults.stable) {
        tables << "not stable\n";
        continue;
      }
      if (onFront) {
        tables << "on the front\n";
        continue;
      }
      // A run that dominates it in a phase ranked by statistics with both errors under the
      // floors is only cheaper, not shown to be as accurate: it does not count.
      bool measured = false;     // some run dominates it where the reference resolves the errors
      bool beyondNoise = false;  // ... by more than the timing noise
      std::ostringstream by;
      for (std::size_t j : fronts[p]) {
        if (!dominates(runs[j], defaults, p, verdicts[p])) continue;
        const Real timeRatio = runs[j].cpuPerSimulated / defaults.cpuPerSimulated;
        const Real errorRatio = rankedError(runs[j], p, verdicts[p]) / rankedError(defaults, p, verdicts[p]);
        by << "; " << describeConfig(runs[j]) << " (" << std::setprecision(3) << timeRatio
           << "x the CPU time, " << errorRatio << "x the error)";
        const bool tiedUnderFloor = !verdicts[p].byDistance && errorRatio == 1 &&
                                    rankedError(defaults, p, verdicts[p]) == verdicts[p].floor();
        if (tiedUnderFloor) continue;
        measured = true;
        beyondNoise = beyondNoise || timeRatio < 1 - kTimingNoise || errorRatio < 1 - kTimingNoise;
      }
      if (!verdicts[p].byDistance) {
        tables << "ranked by shape statistics (reference "
               << (verdicts[p].chaotic ? "chaotic" : "unresolved") << "): ";
      }
      if (!measured) {
        tables << "cheaper runs tie with it under the floor, no difference in error measured";
      } else {
        tables << (beyondNoise ? "DOMINATED beyond the noise" : "dominated only within the noise (10 %)");
      }
      tables << by.str() << "\n";
      if (beyondNoise && options.checkDefaults) status = 3;
    }
  }
  tables << "\nErrors divided by L = " << comparison.length
         << " m where they are lengths; statistics are dimensionless (energy / (M g L), strain, "
            "share of vertices near a body, silhouette coverage distance), each pooled over the "
            "phase. "
            "Bullet (bullet piterations=...) runs its own cloth model: its errors include the "
            "model's difference, not only its integrator's.\n";
  out << tables.str();

  if (!options.csvPath.empty()) {
    writeCsv(options.csvPath, runs, phases, verdicts, fronts);
    out << "csv: " << options.csvPath << "\n";
  }
  if (!options.markdownPath.empty()) {
    std::ofstream markdown(options.markdownPath);
    markdown << tables.str();
    out << (markdown ? "markdown: " : "markdown: could not write ") << options.markdownPath << "\n";
  }
  if (!options.plotPath.empty()) {
    std::ostringstream title;
    title << "Weft curtain: error vs CPU time per phase (reference " << options.referenceIntegrator
          << " h=1/" << std::lround(Real(options.referenceSubsteps) / CurtainScene::kFrameDt) << ")";
    writePlot(options.plotPath, runs, phases, verdicts, fronts, title.str(), out);
  }
  if (status == 3) {
    out << "weft-error-time: SolverSettings{} is dominated beyond the timing noise in a phase the "
           "reference resolves (--check-defaults)\n";
  }
  return status;
}

}  // namespace weft
