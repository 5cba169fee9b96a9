"""The fixed part of an exported OpenSeesPy script: its functions (see ``opensees.py``).

Kept apart from the code that writes the data tables so each reads on its own. The text is
plain Python source using the tables ``NODES``, ``FIX``, ``EQUAL_DOF``, ``SECTIONS``,
``MEMBERS``, ``GROUND_NODES``, ``SPRINGS``, ``SPRING_MATERIALS``, ``VERTICAL_MASS``,
``PALLETS``, ``LEVEL_NODES`` and the constants written above it.
"""

FUNCTIONS = '''
# --- tags ------------------------------------------------------------------------------------
# Nodes: mesh nodes 1..len(NODES), then the fixed ground nodes of GROUND_NODES, then one node
# per pallet (PALLETS). Elements: members 1..len(MEMBERS), then the springs, then (friction
# mode) one zeroLength per pallet. Materials: one per spring, then one per pallet.
N_MEMBERS = len(MEMBERS)
N_STRUCTURE_ELEMENTS = N_MEMBERS + len(SPRINGS)
PALLET_NODE = [p[0] for p in PALLETS]
PALLET_BEAM_NODE = [p[1] for p in PALLETS]
PALLET_ELEMENT = [N_STRUCTURE_ELEMENTS + 1 + n for n in range(len(PALLETS))]
PALLET_LEVEL = [p[4] for p in PALLETS]


def build(pallets=None):
    """Wipe the OpenSees domain and build the rack in it.

    pallets: "friction" (ElasticPP zeroLength per pallet) or "rigid" (equalDOF in ux);
        default PALLET_MODE.
    """
    pallets = PALLET_MODE if pallets is None else pallets
    if pallets not in ("friction", "rigid"):
        raise ValueError(f"pallets must be 'friction' or 'rigid', not {pallets!r}")
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, (x, y) in enumerate(NODES, start=1):
        ops.node(tag, x, y)
    for tag, fx, fy, fr in FIX:
        ops.fix(tag, fx, fy, fr)
    # a semi-rigid beam end is its own node sharing ux, uy with the upright node
    for retained, constrained, dirs in EQUAL_DOF:
        ops.equalDOF(retained, constrained, *dirs)

    # members: dispBeamColumn + Elastic section + consistent mass (see the header)
    ops.geomTransf("Linear", 1)
    for sec, (E, A, I, _rho_a) in enumerate(SECTIONS, start=1):
        ops.section("Elastic", sec, E, A, I)
        ops.beamIntegration("Legendre", sec, sec, 3)
    for tag, (i, j, sec) in enumerate(MEMBERS, start=1):
        ops.element("dispBeamColumn", tag, i, j, 1, sec, "-mass", SECTIONS[sec - 1][3],
                    "-cMass")

    # connector springs (beam-to-upright, base), in seisrack's K so in the Rayleigh damping
    for tag, x, y in GROUND_NODES:
        ops.node(tag, x, y)
        ops.fix(tag, 1, 1, 1)
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

    # pallets: vertical mass on the beam node, horizontal mass on the pallet's own node
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
            mat = len(SPRINGS) + 1 + n
            ops.uniaxialMaterial("ElasticPP", mat, K_INIT, mu * mass * G / K_INIT)
            ops.element("zeroLength", PALLET_ELEMENT[n], beam, node, "-mat", mat, "-dir", 1)

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


def modal(n=6, pallets=None):
    """Build the rack afresh and return the periods [s] of its first ``n`` modes.

    With pallets="friction" each pallet sits on its elastic K_INIT spring; with "rigid" it
    moves with its beam node (compare with ``seisrack modal``, which attaches pallets rigidly).
    """
    build(pallets)
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


def gravity(tol=1e-10, max_iter=25):
    """Load the built rack with its own and its pallets' weight (static, then held constant):
    the members' weight as a uniform load (-beamUniform, the consistent load of seisrack's
    -g M r_y), each pallet's weight on its beam node. The earthquake starts from this state,
    as in seisrack, where a connection carries its gravity moment before the shaking.
    Returns the mean ux of each level's nodes under gravity [m]."""
    ops.timeSeries("Constant", 100)
    ops.pattern("Plain", 100, 100)
    for tag, (i, j, sec) in enumerate(MEMBERS, start=1):
        (xi, yi), (xj, yj) = NODES[i - 1], NODES[j - 1]
        length = math.hypot(xj - xi, yj - yi)
        w = SECTIONS[sec - 1][3] * G  # weight per length [N/m]
        c, s = (xj - xi) / length, (yj - yi) / length
        ops.eleLoad("-ele", tag, "-type", "-beamUniform", -w * c, -w * s)  # local y, local x
    for node, mass in VERTICAL_MASS:
        ops.load(node, 0.0, -mass * G, 0.0)
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
    return [sum(ops.nodeDisp(n, 1) for n in nodes) / len(nodes) for nodes in LEVEL_NODES]


def _setup_transient(ag, dt, pallets, tol, max_iter):
    """Build, apply gravity, set up the transient; returns the gravity level displacements."""
    build(pallets)
    u_g = gravity(tol, max_iter)
    ops.timeSeries("Path", 1, "-dt", float(dt), "-values", *[float(a) for a in ag])
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system(SYSTEM)
    ops.test("NormDispIncr", tol, max_iter)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    return u_g


def history(ag, dt, pallets=None, tol=1e-10, max_iter=25):
    """As run(), but returns the histories, one row per time k dt (k = 0..len(ag)-1):

    {"t": [s], "level_displacement": per step, the mean ux of each level's nodes relative to
    the ground and to the gravity state (as seisrack's beam displacement) [m];
    "spring_deformation": per step, each spring's deformation u_j - u_i [rad or m] (a
    connection: seisrack's hinge rotation, gravity included); "spring_force": its force
    [N m or N]}.
    """
    u_g = _setup_transient(ag, dt, pallets, tol, max_iter)
    springs = range(N_MEMBERS + 1, N_STRUCTURE_ELEMENTS + 1)
    out = {"t": [], "level_displacement": [], "spring_deformation": [], "spring_force": []}

    def sample():
        out["t"].append(ops.getTime())
        out["level_displacement"].append(
            [sum(ops.nodeDisp(n, 1) for n in nodes) / len(nodes) - u_g[lv]
             for lv, nodes in enumerate(LEVEL_NODES)])
        out["spring_deformation"].append([ops.eleResponse(e, "deformation")[0] for e in springs])
        out["spring_force"].append([ops.eleResponse(e, "basicForce")[0] for e in springs])

    sample()
    for step in range(1, len(ag)):
        if ops.analyze(1, dt) != 0 and not _retry(step * dt, dt, tol, max_iter):
            raise RuntimeError(f"OpenSees did not converge at t = {step * dt:g} s")
        sample()
    return out


def run(ag, dt, pallets=None, tol=1e-10, max_iter=25):
    """Build the rack afresh and shake it with a horizontal ground acceleration.

    ag: sequence of ground accelerations [m/s2], sample k at time k dt; dt: [s], also the
    analysis step. Newmark average acceleration (gamma 1/2, beta 1/4), Newton with a
    NormDispIncr test; a step that fails is retried in substeps and with other algorithms,
    and RuntimeError is raised if none converges.

    The rack is first loaded by gravity (``gravity()``). Returns the peak over time of |mean ux
    of each level's nodes| relative to the ground and to the gravity state [m], one per level
    (bottom to top), as seisrack's beam displacement.
    """
    u_g = _setup_transient(ag, dt, pallets, tol, max_iter)
    peaks = [0.0] * len(LEVEL_NODES)
    for step in range(1, len(ag)):
        if ops.analyze(1, dt) != 0 and not _retry(step * dt, dt, tol, max_iter):
            raise RuntimeError(f"OpenSees did not converge at t = {step * dt:g} s")
        for lv, nodes in enumerate(LEVEL_NODES):
            d = abs(sum(ops.nodeDisp(n, 1) for n in nodes) / len(nodes) - u_g[lv])
            peaks[lv] = max(peaks[lv], d)
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
