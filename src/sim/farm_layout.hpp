#pragma once
// Internal to the scenarios: the farm course and the single-condition scenarios as path + world (farm_layout.cpp).
#include <string>

#include "sim/farm_modules.hpp"

namespace drover::sim::detail {

// The ~640 m closed farm course through all eleven conditions (ends at rest where it started).
void buildFarm(Scene& scene);
// One condition alone with a short lead-in and lead-out (name as in scenarioNames()); throws for others.
void buildSingle(const std::string& name, Scene& scene);

}  // namespace drover::sim::detail
