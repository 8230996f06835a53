// Error-vs-time sweep: accuracy against cost on the curtain (bench/results/error-time-curtain.md).
//
// Design note. Every run is the curtain scene with its pin script, stepped frame by frame exactly
// as the curtain runner does, with one SolverSettings changed. Its error is measured against a
// reference run of the same scene: backward Euler at 1/16 of the frame step (or smaller), PCG to
// a 1e-10 residual, Newton-refined, in double precision. The reference is expensive, so it is
// cached in a small binary file keyed by everything that defines it, including a fingerprint of
// the engine (the state hash after two reference frames); a sweep with a different key
// recomputes it. Errors are taken at a few fixed times (not every frame) so that comparing
// costs nothing next to simulating, and divided by the cloth's characteristic length (its rest
// bounding-box diagonal, 2.5 m) to be dimensionless:
//   rms_error     max over sample times of the RMS vertex distance to the reference
//   max_error     max over sample times and vertices of that distance
//   strain_error  max over sample times of |max strain − reference max strain|
//   energy_drift  max over sample times of |E − E_ref| / (M g L), E = kinetic + elastic + gravity
// Wall time is measured around World::step only, in the same run, and given per simulated second;
// with --repeat N the fastest of N identical runs is kept (the machine is shared: noise is real).
// Runs whose step reported Unstable or RolledBack are kept in the CSV, flagged, and left out of
// the Pareto front; such a run stops at the first flagged frame (its errors are then n/a).
//
// What the reference is not: backward Euler is first order, so the reference itself is off from
// the exact solution by O(h_ref). Errors far below the reference's own error (higher-order
// methods at small steps) are therefore measured against the reference, not against the truth;
// the sweep says so in its output. Threads are not swept: the engine steps serially for now.
#include "ErrorTime.h"

#include <weft/scenes/Curtain.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <vector>

namespace weft {
namespace {

using Clock = std::chrono::steady_clock;

// One cloth state at a sample time, with the quantities errors are computed from.
struct Sample {
  Index frame = 0;   // frames stepped when it was taken
  Vec3Array positions, velocities;
  Real maxStrain = 0;
  Real energy = 0;   // J, kinetic + elastic + gravity
};

// One point of the sweep.
struct SweepConfig {
  std::string method;        // "implicit-euler", "implicit-newton", "rk4", ...
  SolverSettings solver;
  bool isDefaults = false;   // SolverSettings{} untouched
};

struct RunResult {
  SweepConfig config;
  Index substeps = 0;            // per frame, as the world planned them
  StepStatus status = StepStatus::Ok;
  bool stable = true;            // neither Unstable nor RolledBack
  Index framesRun = 0;
  Real wallPerSimulated = 0;     // s of wall time per simulated s
  Real cgIterationsPerFrame = 0;
  Real rmsError = 0, maxError = 0, strainError = 0, energyDrift = 0;
};

// Total mechanical energy of a curtain state: kinetic from the velocities, elastic and gravity from
// a probe world that evaluates the same forces at exactly that state (World reports the potential
// energy at the start of its last substep; one tiny step of the probe gives it at the state set).
class EnergyProbe {
 public:
  EnergyProbe(std::shared_ptr<const ClothModel> model, const ClothMaterial& material)
      : m_masses(model->vertexMasses(material.arealDensity)) {
    ClothSettings settings;
    settings.material = material;
    settings.solver.substeps = 1;
    m_cloth = m_world.createCloth(std::move(model), settings).value();
  }

  Real energy(const Vec3Array& positions, const Vec3Array& velocities) {
    if (!m_world.setState(m_cloth, positions, velocities).ok()) {
      return std::numeric_limits<Real>::quiet_NaN();
    }
    m_world.step(1e-12);  // s: only to evaluate the potential energy at the state just set
    Real kinetic = 0;
    for (std::size_t i = 0; i < velocities.size(); ++i) {
      kinetic += 0.5 * m_masses[i] * velocities[i].squaredNorm();
    }
    return kinetic + m_world.stats().potentialEnergy;
  }

 private:
  World m_world;
  ClothId m_cloth;
  std::vector<Real> m_masses;
};

// Steps one curtain with the given solver to the last sample frame, recording samples and time.
RunResult runCurtain(const SweepConfig& config, const std::vector<Index>& sampleFrames,
                     std::vector<Sample>* samples, EnergyProbe& probe, Index size) {
  RunResult result;
  result.config = config;
  CurtainSettings settings;
  settings.size = size;
  settings.solver = config.solver;
  Result<CurtainScene> created = CurtainScene::create(settings);
  if (!created.ok()) {
    result.stable = false;
    result.status = StepStatus::InvalidInput;
    return result;
  }
  CurtainScene& scene = created.value();
  World& world = scene.world();
  result.substeps = world.plannedSubsteps(scene.cloth(), CurtainScene::kFrameDt).value();
  const Index lastFrame = sampleFrames.back();
  double wallSeconds = 0;
  long long cgIterations = 0;
  std::size_t nextSample = 0;
  for (Index frame = 1; frame <= lastFrame; ++frame) {
    const Clock::time_point start = Clock::now();
    const StepStatus status = scene.stepFrame();
    wallSeconds += std::chrono::duration<double>(Clock::now() - start).count();
    result.status |= status;
    cgIterations += world.stats().cgIterations;
    result.framesRun = frame;
    // Unstable or rolled back: the run is out of the front whatever follows, so stop here (the
    // engine's retries make an unstable run slow, and a rolled-back state no longer moves).
    if (hasFlag(status, StepStatus::Unstable) || hasFlag(status, StepStatus::RolledBack)) break;
    if (frame == sampleFrames[nextSample]) {
      Sample sample;
      sample.frame = frame;
      const std::span<const Vec3> x = world.positions(scene.cloth()).value();
      const std::span<const Vec3> v = world.velocities(scene.cloth()).value();
      sample.positions.assign(x.begin(), x.end());
      sample.velocities.assign(v.begin(), v.end());
      sample.maxStrain = world.stats().maxStrain;
      sample.energy = probe.energy(sample.positions, sample.velocities);
      samples->push_back(std::move(sample));
      ++nextSample;
    }
  }
  result.stable = !hasFlag(result.status, StepStatus::Unstable) &&
                  !hasFlag(result.status, StepStatus::RolledBack) &&
                  samples->size() == sampleFrames.size();
  const Real simulated = Real(result.framesRun) * CurtainScene::kFrameDt;
  result.wallPerSimulated = simulated > 0 ? wallSeconds / simulated : 0;
  result.cgIterationsPerFrame = result.framesRun ? Real(cgIterations) / Real(result.framesRun) : 0;
  return result;
}

// ---- reference cache ------------------------------------------------------------------------
// Binary, native endianness: "WEFTREF1", u32 key length, key bytes, u32 samples, u32 vertices,
// then per sample: u32 frame, f64 max strain, f64 energy, 3n f64 positions, 3n f64 velocities.

constexpr char kCacheMagic[8] = {'W', 'E', 'F', 'T', 'R', 'E', 'F', '1'};

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
    writeValue(file, sample.maxStrain);
    writeValue(file, sample.energy);
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
    why = "not a weft-error-time reference file";
    return {};
  }
  std::string storedKey(keyLength, '\0');
  if (!file.read(storedKey.data(), keyLength) || storedKey != key) {
    why = "made for other reference settings";
    return {};
  }
  if (!readValue(file, sampleCount) || !readValue(file, vertexCount)) {
    why = "truncated";
    return {};
  }
  std::vector<Sample> samples(sampleCount);
  for (Sample& sample : samples) {
    std::uint32_t frame = 0;
    if (!readValue(file, frame) || !readValue(file, sample.maxStrain) || !readValue(file, sample.energy)) {
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

// ---- the sweep ------------------------------------------------------------------------------

std::string formatTolerance(Real tolerance) {
  std::ostringstream text;
  text << std::setprecision(1) << std::scientific << tolerance;
  return text.str();
}

std::string describeConfig(const RunResult& run) {
  std::ostringstream text;
  text << run.config.method << " h=1/" << std::lround(run.substeps / CurtainScene::kFrameDt);
  if (run.config.solver.integrator == IntegratorKind::ImplicitEuler) {
    text << " tol=" << formatTolerance(run.config.solver.cgTolerance);
    // The defaults name their stopping test (the series say it in their method name) and the
    // contact-aware tightening (SolverSettings::tightCgTolerance: the residual tolerance of hard
    // substeps, after a self-collision pass with at least that many contacts per vertex).
    if (run.config.isDefaults) {
      text << (run.config.solver.cgStopping == PcgStopping::VelocityError ? " verr" : " residual");
    }
    if (run.config.solver.tightCgTolerance > 0) {
      text << " tight=" << formatTolerance(run.config.solver.tightCgTolerance) << "@"
           << run.config.solver.tightSelfContactDensity;
    }
    text << (run.config.solver.warmStart ? " warm" : " cold");
  }
  if (run.config.solver.substeps == 0) text << " (auto)";
  if (run.config.isDefaults) text << " [defaults]";
  return text.str();
}

std::vector<SweepConfig> sweepConfigs(const ErrorTimeOptions& options) {
  std::vector<Index> substeps, explicitSubsteps;
  std::vector<Real> tolerances;
  std::vector<bool> warmStarts{true, false};
  if (options.full) {
    substeps = {1, 2, 4, 8, 16, 32};
    explicitSubsteps = substeps;
    tolerances = {1e-2, 5e-3, 1e-3, 1e-4, 1e-6, 1e-8};
  } else if (options.quick) {
    substeps = {1, 2, 4, 8};
    explicitSubsteps = {8, 32};
    tolerances = {1e-1, 5e-2, 3e-2, 2e-2, 1e-2, 5e-3, 1e-3, 1e-8};
  } else {
    substeps = {1, 2, 4, 8, 16};
    explicitSubsteps = {4, 8, 16, 32};
    tolerances = {1e-2, 1e-3, 1e-4, 1e-6, 1e-8};
  }
  std::vector<SweepConfig> configs;
  // The engine's defaults, untouched, first.
  configs.push_back({"implicit-euler", SolverSettings{}, true});
  for (const auto& [method, newton] : {std::pair<const char*, int>{"implicit-euler", 0},
                                       std::pair<const char*, int>{"implicit-newton", 2}}) {
    for (Index n : substeps) {
      for (Real tolerance : tolerances) {
        for (bool warm : warmStarts) {
          // In quick mode, cold starts only at the coarsest step: they change little elsewhere.
          if (options.quick && !warm && n != 1) continue;
          // Newton costs ~2-5x per step: in quick mode its finest step is left out.
          if (options.quick && newton > 0 && n > 4) continue;
          SweepConfig config{method, SolverSettings{}, false};
          config.solver.substeps = n;
          config.solver.newtonIterations = newton;
          // A cap high enough that the tolerance, not the cap, ends the solve (the defaults keep
          // their 200; a capped solve is still reported as solver-not-converged).
          config.solver.cgMaxIterations = 1000;
          config.solver.cgTolerance = tolerance;
          // The implicit series are the residual test, named so; the default is the velocity
          // error, which the -verr series sweeps.
          config.solver.cgStopping = PcgStopping::RelativeResidual;
          config.solver.tightCgTolerance = 0;  // every substep to cgTolerance: a uniform grid
          config.solver.warmStart = warm;
          configs.push_back(config);
          // The same step with the velocity-error stopping test (SolverSettings::cgStopping); in
          // quick mode warm starts at the two coarsest steps only.
          if (newton == 0 && warm && (!options.quick || n <= 2)) {
            SweepConfig velocity = config;
            velocity.method = "implicit-euler-verr";
            velocity.solver.cgStopping = PcgStopping::VelocityError;
            configs.push_back(velocity);
          }
        }
      }
    }
  }
  for (IntegratorKind kind : {IntegratorKind::ExplicitEuler, IntegratorKind::SymplecticEuler,
                              IntegratorKind::Midpoint, IntegratorKind::RungeKutta4}) {
    const char* method = integratorName(kind);
    for (Index n : explicitSubsteps) {
      SweepConfig config{method, SolverSettings{}, false};
      config.solver.integrator = kind;
      config.solver.substeps = n;
      configs.push_back(config);
    }
    // The world's automatic substeps: as many as the stability estimate asks for (~90-130 per
    // frame on the curtain), capped at maxSubsteps and then flagged. The practical explicit run;
    // 10-30 s per simulated second, so quick mode keeps only the cheapest (symplectic Euler).
    if (options.quick && kind != IntegratorKind::SymplecticEuler) continue;
    SweepConfig config{method, SolverSettings{}, false};
    config.solver.integrator = kind;
    config.solver.substeps = 0;
    configs.push_back(config);
  }
  return configs;
}

void measureErrors(RunResult& run, const std::vector<Sample>& samples,
                   const std::vector<Sample>& reference, Real length, Real energyScale) {
  if (samples.size() != reference.size()) {
    run.rmsError = run.maxError = run.strainError = run.energyDrift =
        std::numeric_limits<Real>::quiet_NaN();
    return;
  }
  for (std::size_t k = 0; k < samples.size(); ++k) {
    Real sumSquares = 0, largest = 0;
    const std::size_t n = samples[k].positions.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Real distance = (samples[k].positions[i] - reference[k].positions[i]).norm();
      sumSquares += distance * distance;
      largest = std::max(largest, distance);
    }
    run.rmsError = std::max(run.rmsError, std::sqrt(sumSquares / Real(n)) / length);
    run.maxError = std::max(run.maxError, largest / length);
    run.strainError = std::max(run.strainError, std::abs(samples[k].maxStrain - reference[k].maxStrain));
    run.energyDrift = std::max(run.energyDrift, std::abs(samples[k].energy - reference[k].energy) / energyScale);
  }
}

bool dominates(const RunResult& a, const RunResult& b) {
  return a.wallPerSimulated <= b.wallPerSimulated && a.rmsError <= b.rmsError &&
         (a.wallPerSimulated < b.wallPerSimulated || a.rmsError < b.rmsError);
}

void writeCsv(const std::string& path, const std::vector<RunResult>& runs,
              const std::vector<bool>& onFront) {
  std::ofstream file(path);
  file << "method,integrator,substeps,h_s,newton_iterations,cg_tolerance,warm_start,defaults,"
          "status,stable,frames,wall_s_per_sim_s,cg_iterations_per_frame,rms_error,max_error,"
          "strain_error,energy_drift,pareto\n";
  file << std::setprecision(6);
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const RunResult& run = runs[k];
    const SolverSettings& solver = run.config.solver;
    const bool implicit = solver.integrator == IntegratorKind::ImplicitEuler;
    file << run.config.method << ',' << integratorName(solver.integrator) << ',' << run.substeps
         << ',' << CurtainScene::kFrameDt / Real(std::max<Index>(run.substeps, 1)) << ','
         << (implicit ? solver.newtonIterations : 0) << ',';
    if (implicit) file << solver.cgTolerance;
    file << ',' << (implicit ? (solver.warmStart ? "on" : "off") : "") << ','
         << (run.config.isDefaults ? 1 : 0) << ',' << describe(run.status) << ','
         << (run.stable ? 1 : 0) << ',' << run.framesRun << ',' << run.wallPerSimulated << ','
         << run.cgIterationsPerFrame << ',' << run.rmsError << ',' << run.maxError << ','
         << run.strainError << ',' << run.energyDrift << ',' << (onFront[k] ? 1 : 0) << '\n';
  }
}

// Writes the data and a gnuplot script next to the PNG and runs gnuplot. False when gnuplot is
// missing or fails; the message says what to do.
bool writePlot(const std::string& pngPath, const std::vector<RunResult>& runs,
               const std::vector<bool>& onFront, std::ostream& out) {
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    out << "plot: gnuplot is not installed; install it with `apt-get install gnuplot-nox` and run "
           "again (the CSV has every number)\n";
    return false;
  }
  const std::string dataPath = pngPath + ".dat";
  const std::string scriptPath = pngPath + ".gp";
  std::map<std::string, std::vector<const RunResult*>> series;
  for (const RunResult& run : runs) {
    if (run.stable && std::isfinite(run.rmsError) && run.rmsError > 0) series[run.config.method].push_back(&run);
  }
  std::ofstream data(dataPath);
  data << std::setprecision(6);
  std::vector<std::string> titles;
  for (auto& [method, points] : series) {
    std::sort(points.begin(), points.end(), [](const RunResult* a, const RunResult* b) {
      return a->wallPerSimulated < b->wallPerSimulated;
    });
    data << "# " << method << "\n";
    for (const RunResult* run : points) data << run->wallPerSimulated << ' ' << run->rmsError << '\n';
    data << "\n\n";
    titles.push_back(method);
  }
  std::vector<const RunResult*> front, defaults;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    if (onFront[k]) front.push_back(&runs[k]);
    if (runs[k].config.isDefaults && runs[k].stable) defaults.push_back(&runs[k]);
  }
  std::sort(front.begin(), front.end(), [](const RunResult* a, const RunResult* b) {
    return a->wallPerSimulated < b->wallPerSimulated;
  });
  data << "# pareto\n";
  for (const RunResult* run : front) data << run->wallPerSimulated << ' ' << run->rmsError << '\n';
  data << "\n\n# defaults\n";
  for (const RunResult* run : defaults) data << run->wallPerSimulated << ' ' << run->rmsError << '\n';
  data << "\n";
  data.close();

  std::ofstream script(scriptPath);
  script << "set terminal pngcairo size 1100,750 noenhanced\n"
         << "set output '" << pngPath << "'\n"
         << "set logscale xy\nset grid\nset key outside right\n"
         << "set title 'Weft curtain: error vs wall time (reference: backward Euler, h/16)'\n"
         << "set xlabel 'wall time per simulated second [s]'\n"
         << "set ylabel 'RMS vertex error / characteristic length'\n"
         << "plot ";
  for (std::size_t k = 0; k < titles.size(); ++k) {
    script << "'" << dataPath << "' index " << k << " with points pt 7 ps 1.3 title '" << titles[k] << "', ";
  }
  script << "'" << dataPath << "' index " << titles.size()
         << " with steps lw 2 lc rgb 'black' title 'Pareto front', '" << dataPath << "' index "
         << titles.size() + 1 << " with points pt 6 ps 3 lw 2 lc rgb 'red' title 'SolverSettings{}'\n";
  script.close();
  const std::string command = "gnuplot '" + scriptPath + "'";
  if (std::system(command.c_str()) != 0) {
    out << "plot: gnuplot failed on " << scriptPath << "\n";
    return false;
  }
  out << "plot: " << pngPath << " (data " << dataPath << ", script " << scriptPath << ")\n";
  return true;
}

}  // namespace

int runErrorTime(const ErrorTimeOptions& options, std::ostream& out) {
  if (options.scene != "curtain") {
    out << "weft-error-time: scene '" << options.scene << "' is unknown; the only scene is curtain\n";
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
  const Index size = 1;
  // Sample times: settle (0.5 s, 1 s), the curtain swinging back (2 s); --full adds the rod
  // gathering the curtain (5 s, 6 s).
  const std::vector<Real> sampleTimes =
      options.full ? std::vector<Real>{0.5, 1.0, 2.0, 5.0, 6.0} : std::vector<Real>{0.5, 1.0, 2.0};
  std::vector<Index> sampleFrames;
  for (Real t : sampleTimes) sampleFrames.push_back(Index(std::lround(t / CurtainScene::kFrameDt)));

  const CurtainScene probeScene = CurtainScene::create().value();
  const std::shared_ptr<const ClothModel> model = probeScene.sharedModel();
  const ClothMaterial material = CurtainSettings{}.material;
  EnergyProbe probe(model, material);
  const Real length = model->characteristicLength();
  const Real energyScale = model->totalMass(material.arealDensity) * 9.81 * length;

  out << "Weft error-vs-time sweep, curtain size x" << size << ": "
      << model->vertexCount() << " vertices, characteristic length " << length << " m\n"
      << "  samples at";
  for (Real t : sampleTimes) out << ' ' << t << " s";
  out << " (pin script on)\n";

  // The reference.
  SweepConfig referenceConfig{"reference", SolverSettings{}, false};
  referenceConfig.solver.substeps = options.referenceSubsteps;
  referenceConfig.solver.newtonIterations = options.referenceNewtonIterations;
  referenceConfig.solver.cgTolerance = options.referenceCgTolerance;
  referenceConfig.solver.cgStopping = PcgStopping::RelativeResidual;  // the reference: residual ≤ 1e-10
  referenceConfig.solver.tightCgTolerance = 0;  // every substep to the reference's tolerance
  referenceConfig.solver.cgMaxIterations = 5000;
  std::ostringstream keyText;
  keyText << std::setprecision(17) << "weft-error-time reference v1; curtain size " << size
          << "; vertices " << model->vertexCount() << "; implicit-euler substeps "
          << options.referenceSubsteps << " newton " << options.referenceNewtonIterations
          << " cg " << options.referenceCgTolerance << "; frames";
  for (Index frame : sampleFrames) keyText << ' ' << frame;
  {
    // Engine fingerprint: the state hash after the reference's first two frames. Any change of
    // the engine or the scene that alters the reference changes it, so a stale cache is never
    // read back (about 2 % of the reference's cost).
    CurtainSettings settings;
    settings.size = size;
    settings.solver = referenceConfig.solver;
    CurtainScene scene = CurtainScene::create(settings).value();
    for (int frame = 0; frame < 2; ++frame) scene.stepFrame();
    keyText << "; engine fingerprint " << std::hex << scene.world().stateHash() << std::dec;
  }
  const std::string key = keyText.str();
  std::vector<Sample> reference;
  std::string why = "no --reference-cache given";
  if (!options.referenceCache.empty()) reference = loadReference(options.referenceCache, key, why);
  if (!reference.empty()) {
    out << "  reference  read from " << options.referenceCache << "\n";
  } else {
    out << "  reference  computing (" << why << "): backward Euler, " << options.referenceSubsteps
        << " substeps per frame, " << options.referenceNewtonIterations
        << " Newton iterations, PCG to " << options.referenceCgTolerance << " ..." << std::flush;
    const Clock::time_point start = Clock::now();
    const RunResult run = runCurtain(referenceConfig, sampleFrames, &reference, probe, size);
    out << " " << std::chrono::duration<double>(Clock::now() - start).count() << " s, status "
        << describe(run.status) << "\n";
    if (!run.stable) {
      out << "weft-error-time: the reference run is not healthy (" << describe(run.status)
          << "); raise --reference-substeps\n";
      return 1;
    }
    if (!options.referenceCache.empty()) {
      if (saveReference(options.referenceCache, key, reference)) {
        out << "  reference  cached in " << options.referenceCache << "\n";
      } else {
        out << "  reference  could not be written to " << options.referenceCache << "\n";
      }
    }
  }

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
  out << "  sweep      " << configs.size() << " runs\n";
  std::vector<RunResult> runs;
  // Substeps the world picks for each explicit method on its own (its stability estimate).
  std::map<IntegratorKind, Index> stableSubsteps;
  for (const SweepConfig& config : configs) {
    const IntegratorKind kind = config.solver.integrator;
    if (kind == IntegratorKind::ImplicitEuler || stableSubsteps.count(kind)) continue;
    CurtainSettings settings;
    settings.size = size;
    settings.solver.integrator = kind;
    const CurtainScene scene = CurtainScene::create(settings).value();
    stableSubsteps[kind] = scene.world().plannedSubsteps(scene.cloth(), CurtainScene::kFrameDt).value();
  }
  for (const SweepConfig& config : configs) {
    std::vector<Sample> samples;
    const auto stable = stableSubsteps.find(config.solver.integrator);
    if (options.quick && stable != stableSubsteps.end() && config.solver.substeps != 0 &&
        config.solver.substeps < stable->second) {
      // Quick mode does not run what the world predicts unstable: the engine's roll-back and
      // retry make even one frame of it cost tens of seconds. It is reported as unstable.
      RunResult run;
      run.config = config;
      run.substeps = config.solver.substeps;
      run.status = StepStatus::Unstable;
      run.stable = false;
      run.rmsError = run.maxError = run.strainError = run.energyDrift =
          std::numeric_limits<Real>::quiet_NaN();
      if (options.progress) {
        out << "  " << std::left << std::setw(52) << describeConfig(run) << std::right
            << " predicted unstable (needs " << stable->second << " substeps), not run\n";
      }
      runs.push_back(std::move(run));
      continue;
    }
    RunResult run = runCurtain(config, sampleFrames, &samples, probe, size);
    measureErrors(run, samples, reference, length, energyScale);
    // Repeats only re-time: the same settings give the same bits, so errors do not change.
    for (int repeat = 1; repeat < options.repeats && run.stable; ++repeat) {
      std::vector<Sample> again;
      const RunResult rerun = runCurtain(config, sampleFrames, &again, probe, size);
      run.wallPerSimulated = std::min(run.wallPerSimulated, rerun.wallPerSimulated);
    }
    if (options.progress) {
      out << "  " << std::left << std::setw(52) << describeConfig(run) << std::right
          << " time " << std::setw(8) << std::setprecision(3) << run.wallPerSimulated
          << " s/s  rms " << std::setw(9) << std::setprecision(3) << run.rmsError << "  "
          << describe(run.status) << "\n"
          << std::flush;
    }
    runs.push_back(std::move(run));
  }

  // Pareto front over stable runs: wall time against RMS error.
  std::vector<bool> onFront(runs.size(), false);
  for (std::size_t k = 0; k < runs.size(); ++k) {
    if (!runs[k].stable || !std::isfinite(runs[k].rmsError)) continue;
    onFront[k] = true;
    for (std::size_t j = 0; j < runs.size(); ++j) {
      if (j != k && runs[j].stable && std::isfinite(runs[j].rmsError) && dominates(runs[j], runs[k])) {
        onFront[k] = false;
        break;
      }
    }
  }
  std::vector<std::size_t> frontOrder;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    if (onFront[k]) frontOrder.push_back(k);
  }
  std::sort(frontOrder.begin(), frontOrder.end(), [&](std::size_t a, std::size_t b) {
    return runs[a].wallPerSimulated < runs[b].wallPerSimulated;
  });
  out << "\nPareto front (stable runs; error = RMS vertex distance / " << length << " m):\n";
  out << "  " << std::left << std::setw(52) << "configuration" << std::right << std::setw(11)
      << "s per sim s" << std::setw(11) << "rms error" << std::setw(11) << "max error"
      << std::setw(13) << "strain error" << std::setw(13) << "energy drift" << std::setw(9)
      << "CG/frame" << "\n";
  for (std::size_t k : frontOrder) {
    const RunResult& run = runs[k];
    out << "  " << std::left << std::setw(52) << describeConfig(run) << std::right
        << std::setprecision(3) << std::setw(11) << run.wallPerSimulated << std::setw(11)
        << run.rmsError << std::setw(11) << run.maxError << std::setw(13) << run.strainError
        << std::setw(13) << run.energyDrift << std::setw(9) << std::setprecision(4)
        << run.cgIterationsPerFrame << "\n";
  }
  int unstable = 0;
  for (const RunResult& run : runs) unstable += run.stable ? 0 : 1;
  out << "  (" << unstable << " of " << runs.size()
      << " runs reported Unstable or RolledBack and are left out; see the CSV)\n";

  // Where SolverSettings{} sits.
  for (std::size_t k = 0; k < runs.size(); ++k) {
    if (!runs[k].config.isDefaults) continue;
    const RunResult& defaults = runs[k];
    out << "\nSolverSettings{} (" << describeConfig(defaults) << "): "
        << std::setprecision(3) << defaults.wallPerSimulated << " s per simulated s, rms error "
        << defaults.rmsError << ", status " << describe(defaults.status) << "\n";
    if (!defaults.stable) {
      out << "  the defaults are not stable on the curtain\n";
    } else if (onFront[k]) {
      out << "  ON the Pareto front: no run was both faster and more accurate\n";
    } else {
      out << "  NOT on the Pareto front; dominated by:\n";
      bool beyondNoise = false;
      for (std::size_t j : frontOrder) {
        if (!dominates(runs[j], defaults)) continue;
        const Real timeRatio = runs[j].wallPerSimulated / defaults.wallPerSimulated;
        const Real errorRatio = runs[j].rmsError / defaults.rmsError;
        out << "    " << describeConfig(runs[j]) << ": " << std::setprecision(3) << timeRatio
            << "x the time, " << errorRatio << "x the error\n";
        // Beyond noise: clearly faster (> 10 %) at no worse error, or clearly more accurate
        // (> 10 %) at no more time.
        beyondNoise = beyondNoise || timeRatio < 0.9 || errorRatio < 0.9;
      }
      out << (beyondNoise ? "  -> dominated by more than the timing noise (10 %): the defaults "
                            "should move\n"
                          : "  -> only within the timing noise (10 %): on the front as far as "
                            "this run can tell\n");
    }
  }
  out << "\nNote: the reference is first order (backward Euler, h/" << options.referenceSubsteps
      << "); errors well below the reference's own error measure distance to it, not to the exact "
         "solution. Wall times are single runs on a shared machine: differences under ~10 % are "
         "noise (use --repeat to keep the fastest of several runs).\n";

  if (!options.csvPath.empty()) {
    writeCsv(options.csvPath, runs, onFront);
    out << "csv: " << options.csvPath << "\n";
  }
  if (!options.plotPath.empty()) writePlot(options.plotPath, runs, onFront, out);
  if (!options.markdownPath.empty()) {
    std::ofstream markdown(options.markdownPath);
    markdown << "| configuration | s per simulated s | RMS error | max error | strain error | "
                "energy drift | CG per frame |\n|---|---:|---:|---:|---:|---:|---:|\n";
    for (std::size_t k : frontOrder) {
      const RunResult& run = runs[k];
      markdown << "| " << describeConfig(run) << " | " << std::setprecision(3)
               << run.wallPerSimulated << " | " << run.rmsError << " | " << run.maxError << " | "
               << run.strainError << " | " << run.energyDrift << " | " << std::setprecision(4)
               << run.cgIterationsPerFrame << " |\n";
    }
    for (std::size_t k = 0; k < runs.size(); ++k) {
      if (!runs[k].config.isDefaults) continue;
      markdown << "\nSolverSettings{} (" << describeConfig(runs[k]) << "): " << std::setprecision(3)
               << runs[k].wallPerSimulated << " s per simulated s, RMS error " << runs[k].rmsError
               << ", " << (onFront[k] ? "on the Pareto front" : "not on the Pareto front") << ".\n";
    }
    markdown << "\nError = distance to the backward-Euler reference at h/" << options.referenceSubsteps
             << " divided by the cloth's " << length << " m; " << runs.size() << " runs, "
             << unstable << " unstable left out. Wall times are single runs"
             << (options.repeats > 1 ? " (fastest of several)" : "")
             << " on a shared machine: differences under ~10 % are noise.\n";
    out << (markdown ? "markdown: " : "markdown: could not write ") << options.markdownPath << "\n";
  }
  return 0;
}

}  // namespace weft
