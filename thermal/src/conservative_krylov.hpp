// A Krylov solver that keeps the energy invariant exactly (thermal-notes §4 invariant). Internal header.
//
// On the symmetric form y = M^{1/2}T of an insulated problem (no Dirichlet node, K with zero row
// sums), c = M^{1/2}·1 satisfies J c = 0, so c is an eigenvector of the Newton matrix
// A = I − γJ with eigenvalue 1 and the exact correction x* of A x = b has c·x* = c·b: this is
// Σ M T changing only by the source heat. A Krylov solve stopped at its tolerance misses that
// component by the residual's (c·r); with a preconditioner whose inverse does not keep c (bjacobi,
// hypre, Jacobi on a non-uniform M) the energy books then drift at the Krylov tolerance.
// The wrapper solves with the inner Krylov solver, then sets x's component along c to its exact
// value: x += c (c·b − c·x)/(c·c). Since c is an eigenvector of the symmetric A, this removes
// the error's c-component and leaves the rest unchanged (never a worse step, in A's norm). One
// MPI_Allreduce (both dot products fused) per linear solve.
#pragma once

#include "sundials_support.hpp"

namespace frictherm::thermal::detail {

// Takes ownership of inner. c: the invariant vector (copied).
LinSolPtr make_conservative_krylov(LinSolPtr inner, N_Vector c, SUNContext ctx);

}  // namespace frictherm::thermal::detail
