#include "forces/StretchLaw.h"

#include <sstream>

namespace weft {

StretchLaw warpStretchLaw(const ClothMaterial& material) {
  return {material.warpStretchStiffness, material.stretchKneeStrain,
          material.warpStiffenedStretchStiffness};
}

StretchLaw weftStretchLaw(const ClothMaterial& material) {
  return {material.weftStretchStiffness, material.stretchKneeStrain,
          material.weftStiffenedStretchStiffness};
}

std::string stretchLawProblem(const ClothMaterial& material) {
  const Real knee = material.stretchKneeStrain;
  std::ostringstream text;
  if (std::isnan(knee) || knee < 0) {
    text << "material.stretchKneeStrain = " << knee
         << " (strain): must be positive, or 0 or infinity for a linear stretch response";
    return text.str();
  }
  if (knee == 0 || std::isinf(knee)) return {};
  const struct {
    const char* name;
    Real stiffened;
    const char* lowName;
    Real low;
  } directions[] = {
      {"warpStiffenedStretchStiffness", material.warpStiffenedStretchStiffness,
       "warpStretchStiffness", material.warpStretchStiffness},
      {"weftStiffenedStretchStiffness", material.weftStiffenedStretchStiffness,
       "weftStretchStiffness", material.weftStretchStiffness},
  };
  for (const auto& direction : directions) {
    if (!(direction.stiffened >= direction.low) || !std::isfinite(direction.stiffened)) {
      text << "material." << direction.name << " = " << direction.stiffened
           << " N/m: with a stretch knee it must be finite and at least material."
           << direction.lowName << " (" << direction.low
           << " N/m); set stretchKneeStrain to 0 for a linear stretch response";
      return text.str();
    }
  }
  return {};
}

StretchResponse stretchResponse(const StretchLaw& law, Real strain) {
  const Real k0 = law.stiffness;
  StretchResponse response{0.5 * k0 * strain * strain, k0 * strain, k0};
  const Real knee = law.kneeStrain;
  if (!law.stiffens() || !(strain > knee)) return response;
  const Real rise = law.stiffenedStiffness - k0;  // N/m
  const Real past = strain - knee;
  if (past < knee) {
    // The tangent rises linearly over [ε_k, 2 ε_k].
    response.energyDensity += rise * past * past * past / (6 * knee);
    response.tension += rise * past * past / (2 * knee);
    response.tangent += rise * past / knee;
  } else {
    const Real beyond = past - knee;
    response.energyDensity += rise * (knee * knee / 6 + 0.5 * knee * beyond + 0.5 * beyond * beyond);
    response.tension += rise * (past - 0.5 * knee);
    response.tangent = law.stiffenedStiffness;
  }
  return response;
}

}  // namespace weft
