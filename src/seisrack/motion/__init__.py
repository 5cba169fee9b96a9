"""Ground motions: design spectra, response spectra, artificial accelerograms, record files.

Public API (SI units: m/s², s):

- :class:`Record`, :func:`read_record`, :func:`write_record_csv`, :func:`load_builtin_record`,
  :func:`list_builtin_records` — records and files (``records``);
- :class:`EC8Spectrum`, :func:`ec8_spectrum`, :class:`DesignSpectrum` — EN 1998-1 elastic spectra
  and the protocol any target spectrum satisfies (``ec8``);
- :class:`Spectrum`, :func:`response_spectrum` — exact response spectra (``spectra``);
- :func:`generate_ec8_record`, :func:`generate_ec8_suite` — spectrum-compatible accelerograms
  (``synth``);
- :func:`check_ec8_suite`, :func:`read_suite`, :func:`suite_scale_factor` — EN 1998-1
  §3.2.3.1.2 suite report for files or folders, and the common scale factor (``check``);
- :func:`scale_by`, :func:`scale_to_pga`, :func:`scale_to_sa`, :func:`scale_record` — record
  scaling (``scaling``).
"""

from seisrack.motion.check import (
    CheckItem,
    SuiteReport,
    check_ec8_suite,
    read_suite,
    suite_scale_factor,
)
from seisrack.motion.ec8 import DesignSpectrum, EC8Spectrum, damping_correction, ec8_spectrum
from seisrack.motion.records import (
    G,
    Record,
    list_builtin_records,
    load_builtin_record,
    read_record,
    write_record_csv,
)
from seisrack.motion.scaling import scale_by, scale_record, scale_to_pga, scale_to_sa
from seisrack.motion.spectra import Spectrum, response_spectrum
from seisrack.motion.synth import envelope, generate_ec8_record, generate_ec8_suite

__all__ = [
    "G",
    "CheckItem",
    "DesignSpectrum",
    "EC8Spectrum",
    "Record",
    "Spectrum",
    "SuiteReport",
    "check_ec8_suite",
    "damping_correction",
    "ec8_spectrum",
    "envelope",
    "generate_ec8_record",
    "generate_ec8_suite",
    "list_builtin_records",
    "load_builtin_record",
    "read_record",
    "read_suite",
    "response_spectrum",
    "scale_by",
    "scale_record",
    "scale_to_pga",
    "scale_to_sa",
    "suite_scale_factor",
    "write_record_csv",
]
