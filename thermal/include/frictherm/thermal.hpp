#pragma once
// Umbrella header of frictherm::thermal: the nodal conduction problem and its integrators (design §3).
// Knows nothing of MPM.
#include <frictherm/thermal/integrator.hpp>
#include <frictherm/thermal/problem.hpp>
#include <frictherm/thermal/reaction.hpp>
#include <frictherm/thermal/stability.hpp>
