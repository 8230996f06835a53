// The implicit integrators' order and damping (weft-error-time --scene drape | pendulum).
//
// drape: the free drape (scenes/FreeDrape.h, a 1 m sheet released 30° from hanging) for 2 s, against
// BDF2 at h = 1/3840 s with two Newton iterations and the PCG to 1e-11 (shown converged by its
// distance to the same at h = 1/1920 s). Each configuration's error is the largest RMS vertex
// distance over samples every 0.1 s; its observed order is log2 of the error's ratio between a
// step and half of it.
// pendulum: the pendulum (scenes/Pendulum.h) at the default step with each implicit method and
// otherwise default settings, for ten periods: the amplitude kept per period and the period,
// measured from the swing's turning points and zero crossings, beside the closed forms of the
// method on the linear swing (PendulumScene::growthFactor).
#include "BenchClock.h"
#include "ErrorTime.h"

#include <weft/scenes/FreeDrape.h>
#include <weft/scenes/Pendulum.h>

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <utility>
#include <vector>

namespace weft {
namespace {

using bench::threadCpuSeconds;

struct DrapeRun {
  std::vector<Vec3Array> samples;  // every 0.1 s
  Real cgPerFrame = 0;
  Real cpuPerSimulated = 0;
};

constexpr Real kDrapeSeconds = 2.0;
constexpr Index kDrapeSampleFrames = 6;

DrapeRun runDrape(const SolverSettings& solver) {
  FreeDrapeSettings settings;
  settings.solver = solver;
  FreeDrapeScene scene = FreeDrapeScene::create(settings).value();
  DrapeRun run;
  const Index frames = Index(std::lround(kDrapeSeconds / FreeDrapeScene::kFrameDt));
  long long cg = 0;
  double cpu = 0;
  for (Index frame = 1; frame <= frames; ++frame) {
    const double start = threadCpuSeconds();
    scene.stepFrame();
    cpu += threadCpuSeconds() - start;
    cg += scene.world().stats().cgIterations;
    if (frame % kDrapeSampleFrames == 0) {
      const std::span<const Vec3> x = scene.positions();
      run.samples.emplace_back(x.begin(), x.end());
    }
  }
  run.cgPerFrame = Real(cg) / Real(frames);
  run.cpuPerSimulated = cpu / kDrapeSeconds;
  return run;
}

Real rmsDistance(const Vec3Array& a, const Vec3Array& b) {
  Real sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]).squaredNorm();
  return std::sqrt(sum / Real(a.size()));
}

// Largest RMS distance over the samples, and the distance at 1 s (the tenth sample).
std::pair<Real, Real> drapeError(const DrapeRun& run, const DrapeRun& reference) {
  Real largest = 0;
  for (std::size_t k = 0; k < run.samples.size(); ++k) {
    largest = std::max(largest, rmsDistance(run.samples[k], reference.samples[k]));
  }
  return {largest, rmsDistance(run.samples[9], reference.samples[9])};
}

SolverSettings referenceSolver(Index substeps) {
  SolverSettings solver;
  solver.integrator = IntegratorKind::Bdf2;
  solver.substeps = substeps;
  solver.newtonIterations = 2;
  solver.cgTolerance = 1e-11;
  solver.cgStopping = PcgStopping::RelativeResidual;
  solver.tightCgTolerance = 0;
  solver.cgMaxIterations = 5000;
  return solver;
}

int drapeStudy(std::ostream& out) {
  out << "Free drape: 1 m sheet, 21 x 21 vertices, released 30 deg from hanging, ClothMaterial{} (cotton, "
         "no strain limit), no contact, 2 s; error = largest RMS vertex distance over samples "
         "every 0.1 s (m)\n";
  const DrapeRun reference = runDrape(referenceSolver(64));
  const DrapeRun check = runDrape(referenceSolver(32));
  out << "reference: bdf2 h=1/3840 s, 2 Newton iterations, PCG residual 1e-11; its distance to "
         "the same at h=1/1920 s: "
      << std::setprecision(3) << drapeError(check, reference).first << " m\n\n";
  out << "| method | Newton | PCG stop | h (s) | error (m) | at 1 s (m) | order | CG per frame | CPU s per sim s |\n"
      << "|---|---:|---|---|---:|---:|---:|---:|---:|\n";
  for (IntegratorKind kind : {IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2}) {
    for (int newton : {0, 1}) {
      for (bool converged : {true, false}) {
        Real previous = 0;
        for (Index substeps : {1, 2, 4, 8, 16}) {
          SolverSettings solver;  // the defaults: velocity error 0.1, tightened in hard substeps
          solver.integrator = kind;
          solver.substeps = substeps;
          solver.newtonIterations = newton;
          if (converged) {
            solver.cgTolerance = 1e-10;
            solver.cgStopping = PcgStopping::RelativeResidual;
            solver.tightCgTolerance = 0;
            solver.cgMaxIterations = 5000;
          }
          const DrapeRun run = runDrape(solver);
          const auto [error, atOne] = drapeError(run, reference);
          out << "| " << integratorName(kind) << " | " << newton << " | "
              << (converged ? "residual 1e-10" : "default (verr 0.1)") << " | 1/" << 60 * substeps
              << " | " << std::setprecision(3) << error << " | " << atOne << " | ";
          if (previous > 0) out << std::setprecision(2) << std::log2(previous / error);
          out << " | " << std::setprecision(4) << run.cgPerFrame << " | " << std::setprecision(3)
              << run.cpuPerSimulated << " |\n" << std::flush;
          previous = error;
        }
      }
    }
  }
  out << "\nOrder: log2 of the error's ratio between the step above and this one. CPU time of the "
         "stepping thread, one thread.\n";
  return 0;
}

int pendulumStudy(std::ostream& out) {
  out << "Pendulum: L = 1 m, 5 deg amplitude, 1 kg bob on 1e5 N/m springs, no drag or spring "
         "damping; h = 1/60 s (one substep: the default), otherwise SolverSettings{}; ten periods\n\n"
      << "| method | amplitude kept per period: theory | measured | period (s): theory | measured | closed form 2 pi sqrt(L/g) |\n"
      << "|---|---:|---:|---:|---:|---:|\n";
  // Each method as the defaults run it (one linearisation per step), then with one Newton
  // iteration: the single linearisation of the stiff springs' rotation damps the swing by itself.
  for (const auto& [kind, newton] : {std::pair{IntegratorKind::ImplicitEuler, 0},
                                     std::pair{IntegratorKind::ImplicitEuler, 1},
                                     std::pair{IntegratorKind::Bdf2, 0},
                                     std::pair{IntegratorKind::Bdf2, 1}}) {
    PendulumSettings settings;
    settings.solver.integrator = kind;
    settings.solver.newtonIterations = newton;
    PendulumScene scene = PendulumScene::create(settings).value();
    const Real omega = scene.frequency();
    const Real h = PendulumScene::kFrameDt;
    const std::complex<Real> rho = PendulumScene::growthFactor(kind, omega * h);
    const Real theoryPeriod = 2 * std::numbers::pi * h / std::arg(rho);
    const Real theoryKept = std::pow(std::abs(rho), theoryPeriod / h);
    // Turning points (parabola through three samples) and upward zero crossings.
    std::vector<Real> angles{scene.angle()};
    const Index frames = Index(std::ceil(10.5 * 2 * std::numbers::pi / omega / h));
    for (Index frame = 0; frame < frames; ++frame) {
      scene.stepFrame();
      angles.push_back(scene.angle());
    }
    std::vector<Real> peaks, crossings;
    for (std::size_t k = 1; k + 1 < angles.size(); ++k) {
      const Real a = angles[k - 1], b = angles[k], c = angles[k + 1];
      if (b > a && b >= c) {
        const Real curvature = a - 2 * b + c;
        const Real offset = curvature != 0 ? 0.5 * (a - c) / curvature : 0;
        peaks.push_back(b - 0.25 * (a - c) * offset);
      }
      if (a < 0 && b >= 0) crossings.push_back(h * (Real(k - 1) + a / (a - b)));
    }
    Real kept = std::nan(""), period = std::nan("");
    if (peaks.size() >= 3) kept = std::pow(peaks.back() / peaks.front(), 1.0 / Real(peaks.size() - 1));
    if (crossings.size() >= 2) {
      period = (crossings.back() - crossings.front()) / Real(crossings.size() - 1);
    }
    out << "| " << integratorName(kind) << (newton ? " newton " + std::to_string(newton) : std::string())
        << " | " << std::setprecision(5) << theoryKept << " | "
        << kept << " | " << theoryPeriod << " | " << period << " | "
        << 2 * std::numbers::pi / omega << " |\n";
  }
  out << "\nTheory: the method's growth factor rho on the linear swing at z = i omega h "
         "(backward Euler 1/(1 - z), BDF2 (2 + sqrt(1 + 2z))/(3 - 2z)), raised to the steps of "
         "one period 2 pi h / arg rho. The measured amplitude is the ratio of turning points; "
         "BDF2's first step is a backward-Euler step.\n";
  return 0;
}

}  // namespace

int runIntegratorStudy(const ErrorTimeOptions& options, std::ostream& out) {
  if (options.scene == "pendulum") return pendulumStudy(out);
  return drapeStudy(out);
}

}  // namespace weft
