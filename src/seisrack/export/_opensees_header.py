"""The docstring at the top of an exported OpenSeesPy script: what it is and the modelling
choices, for a plane (2D) or a space (3D) rack (see ``opensees.py``)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from seisrack import __version__


def header(model: Any, pallets: str, mu: float | None, k_init: float, record: Any,
           source: str | None, mu_d_differs: bool, materials: Sequence[tuple] = ()) -> str:
    mu_text = (f"mu = {mu:g} for every pallet" if mu is not None
               else "each pallet's mu_static from the rack file")
    mu_note = ("\nNOTE: some pallets have mu_dynamic < mu_static; this model uses mu_static "
               "(it cannot\nhold two coefficients), so it slides later and less than seisrack "
               "there.\n" if mu_d_differs else "")
    kinds = sorted({m[0] for m in materials})
    hyst = (f"\n- connections: nonlinear ([hysteresis]): zeroLength with {', '.join(kinds)} "
            "(see\n  SPRING_MATERIALS); zeroLength deformation u_j - u_i = seisrack's hinge "
            "rotation." if materials else "")
    pd_note = ("\nNOTE: the rack has P-Delta ([second_order]) in seisrack; this script uses a "
               "Linear\ntransformation (GEOM_TRANSF), so it leaves P-Delta out. Set "
               "GEOM_TRANSF = 'PDelta'\nfor OpenSees' chord term (seisrack's form = "
               "\"p_delta_only\"); modal() then applies gravity first.\n"
               if getattr(model, "critical_load_factor", None) is not None else "")
    rec = f"\nGround motion: {record.name} (dt {record.dt:g} s), run by `python` this script.\n" \
        if record is not None else ""
    a0, a1 = model.damping_coefficients
    mesh = model.mesh
    body = (_choices_3d if mesh.ndm == 3 else _choices_2d)(pallets, mu_text, k_init, hyst)
    bars = f" {mesh.trusses.shape[0]} bars," if mesh.trusses.shape[0] else ""
    return f'''"""OpenSeesPy model of: {model.title or "a seisrack rack"}

Exported by seisrack {__version__} (`seisrack export opensees`) from {source or "a compiled rack"}.
{model.n_dof} free DOFs in seisrack, {mesh.nodes.shape[0]} nodes, {mesh.n_el} members,{bars} \
{mesh.springs.shape[0]} connector springs, {model.n_pallets} pallets.
Units: SI (m, kg, s, N, Pa).

Use: `python {{this file}}` prints the first periods; `import` it for build(), modal(n),
gravity() and run(ag, dt) (gravity first, then the ground acceleration ag [m/s2] sampled at
dt [s]; returns the peak level displacements [m] from the gravity state).

Modelling choices (as seisrack's compiled model, node for node):
{body}
- damping: Rayleigh C = a0 M + a1 K_initial with a0 = {a0:.6g}, a1 = {a1:.6g} on the
  structure only (regions when a0 != 0); the pallets' horizontal masses and friction elements
  are undamped.
{_analysis(mesh.ndm)}
{mu_note}{pd_note}{rec}"""
'''


def _choices_2d(pallets: str, mu_text: str, k_init: float, hyst: str) -> str:
    return f"""\
- members: dispBeamColumn, Elastic section, 3-point Gauss-Legendre, Linear transformation,
  consistent mass (-cMass): exactly seisrack's cubic-Hermite beam element. Not
  elasticBeamColumn: in OpenSeesPy 3.7.1 its element mass receives the ground-motion load
  twice under UniformExcitation (measured; see seisrack's benchmarks/opensees_rack.py).
- semi-rigid joints: the beam end is its own node, equalDOF 1 2 to the upright node, with a
  zeroLength Elastic rotational spring; base springs go to fixed extra nodes.{hyst}
- pallets (default mode here: {pallets}): vertical mass on the beam node; horizontal mass on
  the pallet's own node (uy, rz fixed), joined to the beam node by
  * "friction": a zeroLength with ElasticPP(K_INIT, mu m g / K_INIT), a regularised Coulomb
    law with a constant normal force m g and mu_s = mu_d; {mu_text};
    K_INIT = {k_init:g} N/m. Limits: no static/dynamic distinction, no vertical excitation, and the
    elastic stage needs sqrt(K_INIT / m) dt well below 1 (results move with K_INIT and dt);
  * "rigid": equalDOF in ux (no sliding): the pallets move with their beam node."""


def _choices_3d(pallets: str, mu_text: str, k_init: float, hyst: str) -> str:
    return f"""\
- nodes: ndm 3, ndf 6 (ux, uy, uz, rx, ry, rz); x down-aisle, y up, z cross-aisle.
- members: elasticBeamColumn (3D), Linear transformation with the member's vecxz (TRANSFORMS),
  consistent mass (-cMass): seisrack's element (cubic Hermite bending in both planes, linear
  axial and twist). OpenSees 3.7's ElasticBeam3d takes the twist inertia from J, so each
  section is written with J' = Ip and G' = G J / Ip: same torsional stiffness G J, same
  inertia rho Ip L / 3 (SECTIONS: E, A, Iz, Iy, G', J', rho A). Its 3D element mass does not
  have the 2D element's double ground-motion load (measured against dispBeamColumn).
- bracing: Truss bars (-rho rho A -cMass 1, -doRayleigh 1), pin-ended as in seisrack.
- semi-rigid joints: the beam end is its own node, equalDOF 1-5 to the upright node, with a
  zeroLength Elastic spring about z; base springs (about z: base, about x: base_cross) go to
  fixed extra nodes.{hyst}
- pallets (default mode here: {pallets}): each pallet's mass shared equally by its supports
  (the front and the rear beam node), as in seisrack;
  * "friction": one own node per support, coincident with it, with its share of the mass in
    x, y and z, on a flatSliderBearing (frictionModel Coulomb: circular friction in the
    horizontal plane, normal force from its axial force after gravity(), elastic stage
    K_INIT = {k_init:g} N/m, axial stiffness K_AXIAL); a pallet's own nodes share x and z
    (equalDOF), so it slides as one body. The regularised peer of seisrack's exact
    stick-slip: mu_s = mu_d, results move with K_INIT and dt;
    {mu_text};
  * "rigid": the shares are nodal masses of the support nodes in x, y and z (no sliding), the
    mass seisrack's modal analysis uses."""


def _analysis(ndm: int) -> str:
    where = "direction 1, and 3 with agz" if ndm == 3 else "direction 1"
    return (f"- analysis in run(): UniformExcitation ({where}; Path time series),\n  Newmark "
            "average acceleration, Newton + NormDispIncr, Transformation constraints.")
