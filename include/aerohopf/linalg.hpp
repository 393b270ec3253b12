#pragma once
// The linear-algebra layer of aerohopf in one include: direct solvers, block-sparse matrices and
// the shifted/real/bordered builders, BILU(k) with RCM, and the Krylov methods (GCR, GMRES,
// TFQMR, BiCGSTAB) with the compute/solve wrapper krylov_solver. See spec 07.
#include "linalg/block_ilu.hpp"
#include "linalg/block_sparse_matrix.hpp"
#include "linalg/bordered_block_matrix.hpp"
#include "linalg/direct.hpp"
#include "linalg/krylov.hpp"
#include "linalg/krylov_solver.hpp"
#include "linalg/operator.hpp"
#include "linalg/rcm.hpp"
