"""The IEEE-754 bit pattern of a float64 as an int64, and back (an LLVM bitcast: no arithmetic, no rounding).

For non-negative doubles, NaN excluded, the order of the bit patterns read as int64 is the order of the values
(the exponent field lies above the significand, and the sign bit is 0). Integer maxima over such patterns are
reductions LLVM vectorises without fast-math, where a floating-point maximum (ordered, NaN-aware) is not:
``abs_bits(x) = float_bits(x) & ABS_MASK`` is the pattern of |x|, and NaN's patterns lie above every finite
value's and +inf's, so one integer maximum over ``abs_bits`` both finds the largest |x| and tells whether
every value is finite and below a bound.
"""
from __future__ import annotations

import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from .._config import njit

__all__ = ["ABS_MASK", "float_bits", "bits_float", "abs_bits"]

#: every bit but the sign bit of a float64
ABS_MASK = 0x7FFFFFFFFFFFFFFF


# interpreted (mutation testing, debugging): the same patterns through numpy views (numba.config sets its
# attributes from the environment at import, which mypy cannot see)
if numba.config.DISABLE_JIT:  # type: ignore[attr-defined]

    def float_bits(x):
        """The bit pattern of the float64 ``x`` as an int64."""
        return int(np.array(x, dtype=np.float64).view(np.int64))

    def bits_float(k):
        """The float64 whose bit pattern is the int64 ``k``."""
        return float(np.array(k, dtype=np.int64).view(np.float64))

else:

    @intrinsic
    def float_bits(typingctx, x):
        """The bit pattern of the float64 ``x`` as an int64."""
        sig = types.int64(types.float64)

        def codegen(context, builder, signature, args):
            return builder.bitcast(args[0], ir.IntType(64))

        return sig, codegen

    @intrinsic
    def bits_float(typingctx, k):
        """The float64 whose bit pattern is the int64 ``k``."""
        sig = types.float64(types.int64)

        def codegen(context, builder, signature, args):
            return builder.bitcast(args[0], ir.DoubleType())

        return sig, codegen


@njit(inline="always")
def abs_bits(x):
    """The bit pattern of |x| as an int64: ordered as |x| is for non-NaN x, above every finite value for NaN."""
    return float_bits(x) & ABS_MASK
