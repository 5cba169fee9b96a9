"""The seismic design analysis of a rack: EN 1998-1 §4.3.3.3 modal response spectrum analysis
with the EN 16681 / FEM 10.2.08 unit-load factors (issue 24).

- :func:`design_spectrum`: EN 1998-1 §3.2.2.5 design spectrum with q (:mod:`.spectrum`);
- :class:`DesignFactors`: the one overridable factor table, each value with its source
  (:mod:`.factors`);
- :mod:`.combination`: SRSS / CQC (Der Kiureghian) of modes, SRSS / 0.30 rule of directions;
- :mod:`.operators`: named response operators (storey quantities for any rack, member forces
  from :mod:`seisrack.fe.recovery`);
- :func:`design_analysis`: the driver, returning a frozen :class:`DesignResult`;
- :mod:`.sliding_reduction`: the force reduction sliding really gives, beside the factors'.
"""

from seisrack.design.analysis import design_analysis, design_mass
from seisrack.design.combination import cqc, der_kiureghian_rho, srss
from seisrack.design.factors import FACTOR_SOURCES, DesignFactors, parse_factor_overrides
from seisrack.design.result import DesignResult, Quantity, StoreyCheck
from seisrack.design.spectrum import EC8DesignSpectrum, design_spectrum

__all__ = [
    "FACTOR_SOURCES",
    "DesignFactors",
    "DesignResult",
    "EC8DesignSpectrum",
    "Quantity",
    "StoreyCheck",
    "cqc",
    "der_kiureghian_rho",
    "design_analysis",
    "design_mass",
    "design_spectrum",
    "parse_factor_overrides",
    "srss",
]
