// ClothSettingsValidation: the one place that checks a ClothSettings against its model before a
// cloth is made. Every error names the field, its value and unit, and what to do.
#pragma once

#include <weft/engine/World.h>

#include <string>

namespace weft {

/// Empty when `settings` can drive a cloth of `model`; otherwise what is wrong and the fix.
std::string validateClothSettings(const ClothModel* model, const ClothSettings& settings);

}  // namespace weft
