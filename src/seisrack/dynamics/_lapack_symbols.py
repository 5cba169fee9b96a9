"""LAPACK ``dpotrf`` and BLAS ``dsyrk`` for numba-compiled kernels, from SciPy's
``cython_lapack`` and ``cython_blas`` (the BLAS numba's own ``np.dot`` calls).

numba offers neither an in-place Cholesky factorisation (``np.linalg.cholesky`` copies its
input and its result) nor ``syrk``. Each routine is registered with LLVM under a symbol of
its own and declared as an external function: compiled code refers to it by that name, so
numba's on-disk cache stays valid (a ctypes pointer would be a constant address, which numba
refuses to cache). Importing this module registers the symbols; the kernels' source imports it
before its functions are compiled or loaded. Arguments follow the Fortran convention: every
one is a pointer (characters as ``uint8``, integers as ``int32``).
"""

import llvmlite.binding as llvm
from numba import types
from numba.extending import get_cython_function_address


def _external(module: str, name: str, n_args: int) -> types.ExternalFunction:
    symbol = f"seisrack_{name}"
    llvm.add_symbol(symbol, get_cython_function_address(module, name))
    return types.ExternalFunction(symbol, types.void(*([types.voidptr] * n_args)))


#: dsyrk(uplo, trans, n, k, alpha, a, lda, beta, c, ldc): C = alpha A Aᵀ + beta C on one triangle
DSYRK = _external("scipy.linalg.cython_blas", "dsyrk", 10)
#: dpotrf(uplo, n, a, lda, info): Cholesky factor of one triangle, in place
DPOTRF = _external("scipy.linalg.cython_lapack", "dpotrf", 5)
