"""The fixed part of an exported OpenSeesPy script: its functions (see ``opensees.py``).

Kept apart from the code that writes the data tables so each reads on its own. The text is
plain Python source using the tables ``NODES``, ``FIX``, ``EQUAL_DOF``, ``SECTIONS``,
``TRANSFORMS``, ``MEMBERS``, ``TRUSSES``, ``GROUND_NODES``, ``SPRINGS``, ``SPRING_MATERIALS``,
``VERTICAL_MASS``, ``PALLETS``, ``LEVEL_NODES``, ``LEVEL_NODES_Z`` and the
constants written above it (``NDM``, ``NDF``, ``GEOM_TRANSF``, ...). The same functions build a
plane (``NDM = 2``) and a space (``NDM = 3``) rack: where the two differ (the member element,
the pallets) the branch is on ``NDM``.
"""

FUNCTIONS = '''
# --- tags ------------------------------------------------------------------------------------
# Nodes: mesh nodes 1..len(NODES), then the fixed ground nodes of GROUND_NODES, then the
# pallets' own nodes (one per pallet in 2D; in 3D one per support, friction mode only).
# Elements: members 1..len(MEMBERS), then the springs, then the bars (TRUSSES), then (friction
# mode) the pallets' elements. Materials: one per spring, one per pallet (2D friction), one
# per bar, then the two of the 3D sliders. Friction models (3D): one per pallet.
N_MEMBERS = len(MEMBERS)
N_SPRINGS = len(SPRINGS)
N_STRUCTURE_ELEMENTS = N_MEMBERS + N_SPRINGS + len(TRUSSES)
PALLET_NODE = [p[0] for p in PALLETS]
PALLET_BEAM_NODE = [p[1] for p in PALLETS]
PALLET_SUPPORTS = [p[1] if isinstance(p[1], tuple) else (p[1],) for p in PALLETS]
PALLET_ELEMENT = [N_STRUCTURE_ELEMENTS + 1 + sum(len(s) for s in PALLET_SUPPORTS[:n])
                  for n in range(len(PALLETS))]
PALLET_LEVEL = [p[4] for p in PALLETS]
_TRUSS_MATERIAL = N_SPRINGS + len(PALLETS) + 1
_SLIDER_MATERIAL = _TRUSS_MATERIAL + len(TRUSSES)
_BUILT = {"pallets": None}


def build(pallets=None):
    """Wipe the OpenSees domain and build the rack in it.

    pallets: "friction" (2D: ElasticPP zeroLength per pallet; 3D: flatSliderBearing per
        support) or "rigid" (2D: equalDOF in ux; 3D: the pallet's mass on its supports);
        default PALLET_MODE.
    """
    pallets = PALLET_MODE if pallets is None else pallets
    if pallets not in ("friction", "rigid"):
        raise ValueError(f"pallets must be 'friction' or 'rigid', not {pallets!r}")
    ops.wipe()
    ops.model("basic", "-ndm", NDM, "-ndf", NDF)
    for tag, xyz in enumerate(NODES, start=1):
        ops.node(tag, *xyz)
    for tag, *fixed in FIX:
        ops.fix(tag, *fixed)
    # a semi-rigid beam end is its own node sharing the upright node's other DOFs
    for retained, constrained, dirs in EQUAL_DOF:
        ops.equalDOF(retained, constrained, *dirs)

    # members (see the header): consistent mass, one transformation per vecxz
    for tag, vecxz in enumerate(TRANSFORMS, start=1):
        ops.geomTransf(GEOM_TRANSF, tag, *vecxz)
    if NDM == 2:
        for sec, (E, A, I, _rho_a) in enumerate(SECTIONS, start=1):
            ops.section("Elastic", sec, E, A, I)
            ops.beamIntegration("Legendre", sec, sec, 3)
        for tag, (i, j, sec) in enumerate(MEMBERS, start=1):
            ops.element("dispBeamColumn", tag, i, j, 1, sec, "-mass",
                        SECTIONS[sec - 1][3], "-cMass")
    else:
        for tag, (i, j, sec, transf) in enumerate(MEMBERS, start=1):
            E, A, Iz, Iy, G_, J_, rho_a = SECTIONS[sec - 1]
            ops.element("elasticBeamColumn", tag, i, j, A, E, G_, J_, Iy, Iz, transf,
                        "-mass", rho_a, "-cMass")

    # connector springs (beam-to-upright, base), in seisrack's K so in the Rayleigh damping
    for tag, *xyz in GROUND_NODES:
        ops.node(tag, *xyz)
        ops.fix(tag, *([1] * NDF))
    # (nonlinear connections: the [hysteresis] law's material; deformation u_j - u_i is
    # seisrack's hinge rotation)
    for n, (i, j, direction, k) in enumerate(SPRINGS):
        if SPRING_MATERIALS:
            kind, *args = SPRING_MATERIALS[n]
            ops.uniaxialMaterial(kind, n + 1, *args)
        else:
            ops.uniaxialMaterial("Elastic", n + 1, k)
        ops.element("zeroLength", N_MEMBERS + 1 + n, i, j, "-mat", n + 1, "-dir", direction,
                    "-doRayleigh", 1)

    # pin-ended bars (bracing): Truss with consistent mass, damped like the members
    for n, (i, j, E, A, rho_a) in enumerate(TRUSSES):
        ops.uniaxialMaterial("Elastic", _TRUSS_MATERIAL + n, E)
        ops.element("Truss", N_MEMBERS + N_SPRINGS + 1 + n, i, j, A, _TRUSS_MATERIAL + n,
                    "-rho", rho_a, "-cMass", 1, "-doRayleigh", 1)

    if NDM == 2:
        _pallets_2d(pallets)
    else:
        _pallets_3d(pallets)
    _BUILT["pallets"] = pallets

    # damping C = a0 M + a1 K_initial of the structure (initial stiffness, as seisrack; for
    # elastic connections the same as the current one); the pallets' horizontal masses and
    # friction elements carry none (as seisrack's sliders)
    a0, a1 = RAYLEIGH
    if a0 == 0.0:
        ops.rayleigh(0.0, 0.0, a1, 0.0)  # pallet elements have no -doRayleigh: undamped
    else:
        # Nodes first (a0 on the pallets' vertical nodal masses), then the elements with
        # (a0, a1): a node region also sets the factors of every element whose nodes all lie
        # in it, so the element region must come second or the members would lose a1.
        ops.region(1, "-node", *range(1, len(NODES) + 1), "-rayleigh", a0, 0.0, 0.0, 0.0)
        ops.region(2, "-ele", *range(1, N_STRUCTURE_ELEMENTS + 1), "-rayleigh", a0, 0.0, a1,
                   0.0)


def _pallets_2d(pallets):
    """Vertical mass on the beam node, horizontal mass on the pallet's own node."""
    for node, mass in VERTICAL_MASS:
        ops.mass(node, 0.0, mass, 0.0)
    for n, (node, beam, mass, mu, _level) in enumerate(PALLETS):
        x, y = NODES[beam - 1]
        ops.node(node, x, y)
        ops.fix(node, 0, 1, 1)
        ops.mass(node, mass, 0.0, 0.0)
        if pallets == "rigid":
            ops.equalDOF(beam, node, 1)
        else:  # regularised Coulomb: yield force mu m g, initial stiffness K_INIT
            mat = N_SPRINGS + 1 + n
            ops.uniaxialMaterial("ElasticPP", mat, K_INIT, mu * mass * G / K_INIT)
            ops.element("zeroLength", PALLET_ELEMENT[n], beam, node, "-mat", mat, "-dir", 1)


def _pallets_3d(pallets):
    """A pallet's mass shared equally by its supports (front and rear beam node).

    rigid: nodal mass on the supports in x, y and z (seisrack's total mass, as ``seisrack
    modal``). friction: one own node per support, coincident with it, carrying its share in x,
    y and z, on a flatSliderBearing (circular Coulomb friction, initial stiffness K_INIT, axial
    stiffness K_AXIAL, no moment stiffness); the own nodes of a pallet share x and z (equalDOF),
    so the pallet slides as one body on its two supports.
    """
    if pallets == "rigid":
        masses = {}
        for sup, (_node, _beam, mass, _mu, _level) in zip(PALLET_SUPPORTS, PALLETS):
            for s in sup:
                masses[s] = masses.get(s, 0.0) + mass / len(sup)
        for node, m in masses.items():
            ops.mass(node, m, m, m, 0.0, 0.0, 0.0)
        return
    axial, free = _SLIDER_MATERIAL, _SLIDER_MATERIAL + 1
    ops.uniaxialMaterial("Elastic", axial, K_AXIAL)
    ops.uniaxialMaterial("Elastic", free, 0.0)
    for n, (first, sup, mass, mu, _level) in enumerate(PALLETS):
        ops.frictionModel("Coulomb", n + 1, mu)
        share = mass / len(sup)
        for s, beam in enumerate(sup):
            node = first + s
            ops.node(node, *NODES[beam - 1])
            ops.fix(node, 0, 0, 0, 1, 1, 1)
            ops.mass(node, share, share, share, 0.0, 0.0, 0.0)
            # local x (the bearing's axis) vertical: shear in the horizontal plane
            ops.element("flatSliderBearing", PALLET_ELEMENT[n] + s, beam, node, n + 1, K_INIT,
                        "-P", axial, "-T", free, "-My", free, "-Mz", free,
                        "-orient", 0.0, 1.0, 0.0, 1.0, 0.0, 0.0)
            if s:
                ops.equalDOF(first, node, 1, 3)


def _pallet_weights():
    """(node, weight [N]) of the pallets where the built model holds their vertical mass."""
    if NDM == 3 and _BUILT["pallets"] == "friction":
        return [(first + s, mass * G / len(sup))
                for sup, (first, _b, mass, _mu, _lv) in zip(PALLET_SUPPORTS, PALLETS)
                for s in range(len(sup))]
    return [(node, mass * G) for node, mass in VERTICAL_MASS]


def modal(n=6, pallets=None, gravity_first=None):
    """Build the rack afresh and return the periods [s] of its first ``n`` modes.

    With pallets="rigid" the pallets move with their beams (compare with ``seisrack modal``,
    which attaches them rigidly); with "friction" each sits on its elastic K_INIT stage.
    gravity_first: apply gravity() before the eigen analysis; default when GEOM_TRANSF is
    "PDelta" (the geometric stiffness needs the axial forces) or a 3D rack's pallets are on
    their sliders (which need their normal force).
    """
    build(pallets)
    if gravity_first is None:
        gravity_first = GEOM_TRANSF != "Linear" or (NDM == 3 and _BUILT["pallets"] == "friction")
    if gravity_first:
        gravity()
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")  # ARPACK factors through it (SparseSYM gave wrong modes)
    lam = ops.eigen(EIGEN_SOLVER, n)
    return [2.0 * math.pi / math.sqrt(v) for v in lam]


def _retry(t_target, dt, tol, max_iter):
    """Reach t_target in substeps, with other algorithms if Newton fails: True on success."""
    for n_sub, algorithm in ((10, ("Newton",)), (100, ("Newton",)),
                             (10, ("ModifiedNewton", "-initial")), (10, ("KrylovNewton",))):
        ops.test("NormDispIncr", tol, 4 * max_iter)
        ops.algorithm(*algorithm)
        ok = True
        while ok and t_target - ops.getTime() > 1e-12:
            h = min(dt / n_sub, t_target - ops.getTime())
            ok = ops.analyze(1, h) == 0
        if ok:
            ops.test("NormDispIncr", tol, max_iter)
            ops.algorithm("Newton")
            return True
    return False


def _level_means(levels, direction):
    return [sum(ops.nodeDisp(n, direction) for n in nodes) / len(nodes) for nodes in levels]


def _pallet_sliding():
    """Per pallet, its displacement relative to the mean of its supports, per horizontal
    direction [m] (0 when the pallets are rigid in 3D: they have no node of their own)."""
    dirs = (1,) if NDM == 2 else (1, 3)
    out = []
    for first, sup in zip(PALLET_NODE, PALLET_SUPPORTS):
        if NDM == 3 and _BUILT["pallets"] == "rigid":
            out.append([0.0] * len(dirs))
            continue
        out.append([ops.nodeDisp(first, d) - sum(ops.nodeDisp(s, d) for s in sup) / len(sup)
                    for d in dirs])
    return out


def _self_weight():
    """{node: load per DOF slot} of the members' and bars' weight as nodal loads: the
    consistent load of a uniform load w = rho A g per length (seisrack's -g M r_y), i.e. -w L/2
    vertically at each end and, in each bending plane, the fixed-end moments of the load's
    transverse component q: q L^2/12 at end i, -q L^2/12 at end j (about local z; about local
    y the opposite sign, since there the rotation is -dw/dx)."""
    out = {}

    def add(node, f):
        row = out.setdefault(node, [0.0] * NDF)
        for k, v in enumerate(f):
            row[k] += v

    for i, j, sec, *transf in MEMBERS:
        xi, xj = NODES[i - 1], NODES[j - 1]
        d = [b - a for a, b in zip(xi, xj)]
        length = math.sqrt(sum(c * c for c in d))
        ex = [c / length for c in d]
        w = SECTIONS[sec - 1][-1] * G
        c12 = w * length * length / 12.0
        if NDM == 2:
            m = -c12 * ex[0]  # q_y L^2/12 with q_y = -w * (local y)_Y = -w * ex[0]
            fi, fj = [0.0, -w * length / 2, m], [0.0, -w * length / 2, -m]
        else:
            v = TRANSFORMS[transf[0] - 1]
            ey = [v[1] * ex[2] - v[2] * ex[1], v[2] * ex[0] - v[0] * ex[2],
                  v[0] * ex[1] - v[1] * ex[0]]
            n = math.sqrt(sum(c * c for c in ey))
            ey = [c / n for c in ey]
            ez = [ex[1] * ey[2] - ex[2] * ey[1], ex[2] * ey[0] - ex[0] * ey[2],
                  ex[0] * ey[1] - ex[1] * ey[0]]
            # local moments (0, -q_z c, q_y c) with q = -w * (local axis)_Y, to global axes
            my, mz = c12 * ez[1], -c12 * ey[1]
            m = [my * a + mz * b for a, b in zip(ey, ez)]
            fi = [0.0, -w * length / 2, 0.0, *m]
            fj = [0.0, -w * length / 2, 0.0, *(-c for c in m)]
        add(i, fi)
        add(j, fj)
    for i, j, _E, _A, rho_a in TRUSSES:
        length = math.dist(NODES[i - 1], NODES[j - 1])
        f = [0.0] * NDF
        f[1] = -rho_a * G * length / 2
        add(i, f)
        add(j, f)
    return out


def gravity(tol=1e-10, max_iter=25):
    """Load the built rack with its own and its pallets' weight (static, then held constant):
    the members' and bars' weight as their consistent nodal loads (``_self_weight``, seisrack's
    -g M r_y) and each pallet's weight where its vertical mass is. The earthquake starts from
    this state, as in seisrack, where a connection carries its gravity moment before the
    shaking. Returns the mean ux of each level's nodes under gravity [m]."""
    ops.timeSeries("Constant", 100)
    ops.pattern("Plain", 100, 100)
    for node, f in _self_weight().items():
        ops.load(node, *f)
    for node, weight in _pallet_weights():
        f = [0.0] * NDF
        f[1] = -weight
        ops.load(node, *f)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system(SYSTEM)
    ops.test("NormDispIncr", tol, max_iter)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 1.0)
    ops.analysis("Static")
    if ops.analyze(1) != 0:
        raise RuntimeError("OpenSees: the static gravity analysis did not converge")
    ops.loadConst("-time", 0.0)
    ops.wipeAnalysis()
    return _level_means(LEVEL_NODES, 1)


def _setup_transient(ag, dt, pallets, tol, max_iter, agz=None):
    """Build, apply gravity, set up the transient; returns the gravity state (level means in
    x, in z, pallet sliding)."""
    if agz is not None and NDM != 3:
        raise ValueError("a cross-aisle component agz needs a 3D rack")
    build(pallets)
    gravity(tol, max_iter)
    state = (_level_means(LEVEL_NODES, 1), _level_means(LEVEL_NODES_Z, 3), _pallet_sliding())
    ops.timeSeries("Path", 1, "-dt", float(dt), "-values", *[float(a) for a in ag])
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    if agz is not None:
        ops.timeSeries("Path", 2, "-dt", float(dt), "-values", *[float(a) for a in agz])
        ops.pattern("UniformExcitation", 2, 3, "-accel", 2)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system(SYSTEM)
    ops.test("NormDispIncr", tol, max_iter)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    return state


def history(ag, dt, pallets=None, tol=1e-10, max_iter=25, agz=None):
    """As run(), but returns the histories, one row per time k dt (k = 0..len(ag)-1):

    {"t": [s], "level_displacement": per step, the mean ux of each level's nodes relative to
    the ground and to the gravity state (as seisrack's beam displacement) [m];
    "level_displacement_z": the same cross-aisle (3D; empty rows in 2D);
    "pallet_sliding": per step, per pallet, its displacement relative to the mean of its
    supports in each horizontal direction, from the gravity state [m];
    "spring_deformation": per step, each spring's deformation u_j - u_i [rad or m] (a
    connection: seisrack's hinge rotation, gravity included); "spring_force": its force
    [N m or N]}.
    """
    ux0, uz0, s0 = _setup_transient(ag, dt, pallets, tol, max_iter, agz)
    springs = range(N_MEMBERS + 1, N_MEMBERS + N_SPRINGS + 1)
    out = {"t": [], "level_displacement": [], "level_displacement_z": [],
           "pallet_sliding": [], "spring_deformation": [], "spring_force": []}

    def sample():
        out["t"].append(ops.getTime())
        out["level_displacement"].append(
            [u - u0 for u, u0 in zip(_level_means(LEVEL_NODES, 1), ux0)])
        out["level_displacement_z"].append(
            [u - u0 for u, u0 in zip(_level_means(LEVEL_NODES_Z, 3), uz0)])
        out["pallet_sliding"].append([[a - b for a, b in zip(p, p0)]
                                      for p, p0 in zip(_pallet_sliding(), s0)])
        out["spring_deformation"].append([ops.eleResponse(e, "deformation")[0] for e in springs])
        out["spring_force"].append([ops.eleResponse(e, "basicForce")[0] for e in springs])

    sample()
    for step in range(1, len(ag)):
        if ops.analyze(1, dt) != 0 and not _retry(step * dt, dt, tol, max_iter):
            raise RuntimeError(f"OpenSees did not converge at t = {step * dt:g} s")
        sample()
    return out


def run(ag, dt, pallets=None, tol=1e-10, max_iter=25, agz=None):
    """Build the rack afresh and shake it with a horizontal ground acceleration.

    ag: sequence of down-aisle ground accelerations [m/s2], sample k at time k dt; dt: [s],
    also the analysis step; agz: the cross-aisle component (3D racks), same dt and length.
    Newmark average acceleration (gamma 1/2, beta 1/4), Newton with a NormDispIncr test; a
    step that fails is retried in substeps and with other algorithms, and RuntimeError is
    raised if none converges.

    The rack is first loaded by gravity (``gravity()``). Returns the peak over time of |mean ux
    of each level's nodes| relative to the ground and to the gravity state [m], one per level
    (bottom to top), as seisrack's beam displacement.
    """
    u_g = _setup_transient(ag, dt, pallets, tol, max_iter, agz)[0]
    peaks = [0.0] * len(LEVEL_NODES)
    for step in range(1, len(ag)):
        if ops.analyze(1, dt) != 0 and not _retry(step * dt, dt, tol, max_iter):
            raise RuntimeError(f"OpenSees did not converge at t = {step * dt:g} s")
        for lv, d in enumerate(_level_means(LEVEL_NODES, 1)):
            peaks[lv] = max(peaks[lv], abs(d - u_g[lv]))
    return peaks


if __name__ == "__main__":
    print(TITLE)
    print(f"{'mode':>4} {'period [s]':>11}   (pallets {PALLET_MODE})")
    for k, T in enumerate(modal(6), start=1):
        print(f"{k:>4} {T:>11.5f}")
    if RECORD is not None:
        peaks = run(RECORD["accel"], RECORD["dt"])
        print(f"peak level displacement under {RECORD['name']} [mm]:",
              " ".join(f"{1e3 * d:.3f}" for d in peaks))
'''
