// Umbrella header for the thermal module (design §3).
#pragma once

#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/problem.hpp"
#include "frictherm/thermal/reaction.hpp"
#include "frictherm/thermal/stability.hpp"
