"""seisrack: earthquake response of steel pallet racks with sliding pallets."""

from seisrack.errors import FileFormatError, InputError, SeisrackError, SolverError

__version__ = "0.1.0"

__all__ = ["FileFormatError", "InputError", "SeisrackError", "SolverError", "__version__"]
