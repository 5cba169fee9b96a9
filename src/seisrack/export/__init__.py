"""Writers of a compiled rack for other programs.

- :func:`opensees_script`: a standalone OpenSeesPy script of the same rack
  (``seisrack export opensees``; see ``docs/user/export_opensees.md``).
"""

from seisrack.export.opensees import opensees_script

__all__ = ["opensees_script"]
