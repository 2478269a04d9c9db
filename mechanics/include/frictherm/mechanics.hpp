#pragma once
// Umbrella header of frictherm::mechanics: explicit MPM with multimaterial and penalty contact and
// frictional work (design §2). Knows nothing of heat solvers.
#include <frictherm/mechanics/boundary_points.hpp>
#include <frictherm/mechanics/contact.hpp>
#include <frictherm/mechanics/ebs.hpp>
#include <frictherm/mechanics/ellipse_packing.hpp>
#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/friction.hpp>
#include <frictherm/mechanics/friction_expression.hpp>
#include <frictherm/mechanics/geometry.hpp>
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/image.hpp>
#include <frictherm/mechanics/loads.hpp>
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/microstructure.hpp>
#include <frictherm/mechanics/mie_gruneisen.hpp>
#include <frictherm/mechanics/mie_gruneisen_params.hpp>
#include <frictherm/mechanics/particles.hpp>
#include <frictherm/mechanics/penalty_contact.hpp>
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step_timing.hpp>
#include <frictherm/mechanics/time_function.hpp>
#include <frictherm/mechanics/transfer.hpp>
#include <frictherm/mechanics/types.hpp>
