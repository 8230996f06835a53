#include "ClothSettingsValidation.h"

#include <weft/engine/InputLimits.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace weft {
namespace {

std::string checkNonNegative(const char* field, Real value, const char* unit) {
  if (std::isfinite(value) && value >= 0) return {};
  std::ostringstream text;
  text << field << " = " << value << " " << unit << ": must be finite and at least 0";
  return text.str();
}

std::string checkPositive(const char* field, Real value, const char* unit) {
  if (std::isfinite(value) && value > 0) return {};
  std::ostringstream text;
  text << field << " = " << value << " " << unit << ": must be finite and greater than 0";
  return text.str();
}

// 0 and +infinity both mean "no limit"; NaN and negatives are mistakes.
std::string checkStrainLimit(Real value) {
  if (value >= 0) return {};
  std::ostringstream text;
  text << "material.strainLimit = " << value
       << " (strain l / l_rest - 1): must be at least 0; use 0 or infinity to turn strain "
          "limiting off";
  return text.str();
}

// A level at or above which a substep is hard (SolverSettings::tightPinTravel,
// tightSelfContactDensity): any positive value, +infinity included (never hard); 0, negatives and
// NaN are mistakes.
std::string checkHardSubstepThreshold(const char* field, Real value, const char* unit,
                                      const char* infinityMeans) {
  if (value > 0) return {};
  std::ostringstream text;
  text << field << " = " << value << " (" << unit << "): must be greater than 0 (infinity = "
       << infinityMeans << "; tightCgTolerance = 0 turns the tightening off)";
  return text.str();
}

// Every material, spring and mass value of `settings` within kMaxMaterialValue (signs, NaN and
// infinity have their own checks and messages).
std::string magnitudeProblem(const ClothSettings& settings) {
  const ClothMaterial& m = settings.material;
  const MassSpringMaterial& s = settings.springs;
  const struct {
    const char* field;
    Real value;
    const char* unit;
  } fields[] = {
      {"material.arealDensity", m.arealDensity, "kg/m²"},
      {"material.warpStretchStiffness", m.warpStretchStiffness, "N/m"},
      {"material.weftStretchStiffness", m.weftStretchStiffness, "N/m"},
      {"material.shearStiffness", m.shearStiffness, "N/m"},
      {"material.bendingStiffness", m.bendingStiffness, "N·m"},
      {"material.warpRestScale", m.warpRestScale, ""},
      {"material.weftRestScale", m.weftRestScale, ""},
      {"material.stretchDamping", m.stretchDamping, "N·s/m"},
      {"material.shearDamping", m.shearDamping, "N·s/m"},
      {"material.bendingDamping", m.bendingDamping, "N·m·s"},
      {"material.airDrag", m.airDrag, "N·s/m³"},
      {"material.thickness", m.thickness, "m"},
      {"material.friction", m.friction, ""},
      {"springs.structuralStiffness", s.structuralStiffness, "N/m"},
      {"springs.shearStiffness", s.shearStiffness, "N/m"},
      {"springs.flexionStiffness", s.flexionStiffness, "N/m"},
      {"springs.structuralDamping", s.structuralDamping, "N·s/m"},
      {"springs.shearDamping", s.shearDamping, "N·s/m"},
      {"springs.flexionDamping", s.flexionDamping, "N·s/m"},
  };
  auto tooLarge = [](const std::string& field, Real value, const char* unit) {
    std::ostringstream text;
    text << "cloth settings: " << field << " = " << value << (*unit ? " " : "") << unit
         << " is above " << kMaxMaterialValue
         << " (kMaxMaterialValue), the largest value whose products the solver's arithmetic "
            "carries; give a physical value (a stiffer cloth is better made with "
            "material.strainLimit)";
    return text.str();
  };
  for (const auto& field : fields) {
    if (std::isfinite(field.value) && field.value > kMaxMaterialValue) {
      return tooLarge(field.field, field.value, field.unit);
    }
  }
  for (std::size_t i = 0; i < settings.vertexMasses.size(); ++i) {
    const Real mass = settings.vertexMasses[i];
    if (std::isfinite(mass) && mass > kMaxMaterialValue) {
      return tooLarge("vertexMasses[" + std::to_string(i) + "]", mass, "kg");
    }
  }
  return {};
}


// The first vertex that `settings`' placement puts beyond kMaxCoordinate.
std::string placementProblem(const ClothModel& model, const ClothSettings& settings) {
  if (!settings.translation.allFinite() || !settings.rotation.allFinite()) return {};
  for (Index i = 0; i < model.vertexCount(); ++i) {
    const Vec3 x = settings.rotation * model.restPositions()[i] + settings.translation;
    if (!(x.cwiseAbs().maxCoeff() > kMaxCoordinate)) continue;
    std::ostringstream text;
    text << "cloth settings: translation (" << settings.translation.x() << ", "
         << settings.translation.y() << ", " << settings.translation.z() << ") m puts vertex " << i
         << " at (" << x.x() << ", " << x.y() << ", " << x.z() << ") m, beyond the "
         << kMaxCoordinate
         << " m a coordinate may have (kMaxCoordinate, where doubles still resolve 0.1 nm); keep "
            "the simulation near the origin (move the origin with the player)";
    return text.str();
  }
  return {};
}

}  // namespace

std::string validateClothSettings(const ClothModel* model, const ClothSettings& settings) {
  if (std::string problem = magnitudeProblem(settings); !problem.empty()) return problem;
  if (model) {
    if (std::string problem = placementProblem(*model, settings); !problem.empty()) return problem;
  }
  if (!model) return "ClothModel is null: build one with ClothModel::grid() or fromMesh()";
  const ClothMaterial& m = settings.material;
  const MassSpringMaterial& s = settings.springs;
  const SolverSettings& solver = settings.solver;
  for (const std::string& problem : {
           checkPositive("material.arealDensity", m.arealDensity, "kg/m²"),
           checkNonNegative("material.warpStretchStiffness", m.warpStretchStiffness, "N/m"),
           checkNonNegative("material.weftStretchStiffness", m.weftStretchStiffness, "N/m"),
           checkNonNegative("material.shearStiffness", m.shearStiffness, "N/m"),
           checkNonNegative("material.bendingStiffness", m.bendingStiffness, "N·m"),
           checkPositive("material.warpRestScale", m.warpRestScale, ""),
           checkPositive("material.weftRestScale", m.weftRestScale, ""),
           checkNonNegative("material.stretchDamping", m.stretchDamping, "N·s/m"),
           checkNonNegative("material.shearDamping", m.shearDamping, "N·s/m"),
           checkNonNegative("material.bendingDamping", m.bendingDamping, "N·m·s"),
           checkNonNegative("material.airDrag", m.airDrag, "N·s/m³"),
           checkPositive("material.thickness", m.thickness, "m"),
           checkNonNegative("material.friction", m.friction, ""),
           checkStrainLimit(m.strainLimit),
           checkNonNegative("springs.structuralStiffness", s.structuralStiffness, "N/m"),
           checkNonNegative("springs.shearStiffness", s.shearStiffness, "N/m"),
           checkNonNegative("springs.flexionStiffness", s.flexionStiffness, "N/m"),
           checkNonNegative("springs.structuralDamping", s.structuralDamping, "N·s/m"),
           checkNonNegative("springs.shearDamping", s.shearDamping, "N·s/m"),
           checkNonNegative("springs.flexionDamping", s.flexionDamping, "N·s/m"),
           checkPositive("solver.maxImplicitStep", solver.maxImplicitStep, "s"),
           checkPositive("solver.cgTolerance", solver.cgTolerance, ""),
           checkNonNegative("solver.selfContactStiffness", solver.selfContactStiffness,
                            "multiples of the stretch stiffness; 0 = off"),
           checkNonNegative("solver.maxPinTravelPerSubstep", solver.maxPinTravelPerSubstep,
                            "mean edge lengths (0 = no limit)"),
           checkNonNegative("solver.pinTeleportDistance", solver.pinTeleportDistance,
                            "cloth sizes (0 = pins never teleport the cloth)"),
           checkNonNegative("solver.pinTeleportAngle", solver.pinTeleportAngle,
                            "rad (0 = a turn of the pins never teleports the cloth)"),
           checkHardSubstepThreshold("solver.tightPinTravel", solver.tightPinTravel,
                                     "mean edge lengths per substep",
                                     "pins never make a substep hard"),
           checkHardSubstepThreshold("solver.tightSelfContactDensity",
                                     solver.tightSelfContactDensity, "self-contacts per vertex",
                                     "self-contact never makes a substep hard"),
       }) {
    if (!problem.empty()) return "cloth settings: " + problem;
  }
  if (int(solver.integrator) < int(IntegratorKind::ExplicitEuler) ||
      int(solver.integrator) > int(IntegratorKind::Bdf2)) {
    return "cloth settings: solver.integrator = " + std::to_string(int(solver.integrator)) +
           " is not an IntegratorKind; use one of the enumerators";
  }
  if (settings.forceModel != ForceModel::BaraffWitkin && settings.forceModel != ForceModel::MassSpring) {
    return "cloth settings: forceModel = " + std::to_string(int(settings.forceModel)) +
           " is not a ForceModel; use BaraffWitkin or MassSpring";
  }
  if (!(solver.tightCgTolerance >= 0 && solver.tightCgTolerance < 1)) {
    std::ostringstream text;
    text << "cloth settings: solver.tightCgTolerance = " << solver.tightCgTolerance
         << " (relative residual): must be at least 0 and below 1 (0 = hard substeps are not "
            "tightened)";
    return text.str();
  }
  if (solver.cgMaxIterations < 1) return "cloth settings: solver.cgMaxIterations must be at least 1";
  if (solver.newtonIterations < 0) return "cloth settings: solver.newtonIterations must be at least 0";
  if (solver.maxSubsteps < 1) return "cloth settings: solver.maxSubsteps must be at least 1";
  if (!settings.translation.allFinite() || !settings.rotation.allFinite()) {
    return "cloth settings: translation or rotation contains NaN or infinity";
  }
  if (!(settings.rotation.transpose() * settings.rotation).isApprox(Mat3::Identity(), 1e-6) ||
      settings.rotation.determinant() < 0) {
    return "cloth settings: rotation is not a proper rotation matrix (orthonormal, det +1)";
  }
  if (!settings.vertexMasses.empty()) {
    if (settings.vertexMasses.size() != model->vertexCount()) {
      return "cloth settings: vertexMasses has " + std::to_string(settings.vertexMasses.size()) +
             " entries for a model of " + std::to_string(model->vertexCount()) +
             " vertices; give one mass per vertex, or none to use material.arealDensity";
    }
    for (std::size_t i = 0; i < settings.vertexMasses.size(); ++i) {
      if (!(std::isfinite(settings.vertexMasses[i]) && settings.vertexMasses[i] > 0)) {
        std::ostringstream text;
        text << "cloth settings: vertexMasses[" << i << "] = " << settings.vertexMasses[i]
             << " kg: must be finite and greater than 0";
        return text.str();
      }
    }
  }
  std::vector<Index> pins = settings.pinnedVertices;
  std::sort(pins.begin(), pins.end());
  for (std::size_t k = 0; k < pins.size(); ++k) {
    if (pins[k] >= model->vertexCount()) {
      return "cloth settings: pinned vertex " + std::to_string(pins[k]) +
             " does not exist (the model has " + std::to_string(model->vertexCount()) + " vertices)";
    }
    if (k > 0 && pins[k] == pins[k - 1]) {
      return "cloth settings: vertex " + std::to_string(pins[k]) + " is pinned twice; list it once";
    }
  }
  return {};
}

}  // namespace weft
