// Weft.h: the whole public engine API in one include, for code that embeds the engine.
//
//   #include <weft/Weft.h>   // World, ClothModel, materials, presets, settings, stats, views
//
// Only the engine's public headers (and, through them, weft/Math.h, weft/Result.h and the
// TaskSystem a World can share). Not weft::render: drawing stays outside the engine, and a game
// that draws with its own renderer should not need GL headers. Not src/ internals either.
#pragma once

#include <weft/engine/ClothModel.h>
#include <weft/engine/FabricPresets.h>
#include <weft/engine/FixedStepAccumulator.h>
#include <weft/engine/Material.h>
#include <weft/engine/RenderView.h>
#include <weft/engine/SolverSettings.h>
#include <weft/engine/StepBudget.h>
#include <weft/engine/StepStats.h>
#include <weft/engine/World.h>
