"""A small co-simulation master for the engine FMU (EngineMountChassis, scene 3) on the body FMU
(EngineMountBody), on fmpy's low-level API, with three coupling algorithms at a fixed step H.

``jacobi``
    Both FMUs step over [t, t+H] on the other's outputs at t, held (zero-order hold).
``gauss_seidel``
    The engine steps first on the body motion at t, held; the body then steps under the force
    ramp from the engine's force at t to its force at t+H.
``interface_jacobian``
    A linearly implicit coupling step in the spirit of Kübler & Schiehlen (2000, "Two methods of
    simulator coupling", linearly implicit modular integration) and of the interface-Jacobian-
    based co-simulation of Sadjina et al. (2019, "Distributed co-simulation of maritime systems
    and operations"): the unknown of the step is the force increment ΔF over it. The interface condition at t+H — the force the engine
    applies equals the force the body was driven with — is linearised with the partial
    derivatives the FMUs provide (``fmi2GetDirectionalDerivative``): the engine's mount tangent
    stiffness K = ∂F/∂r and damping C = ∂F/∂v w.r.t. the body motion, and the body's response
    to a force-ramp increment. The linear equation (I − K·S_r − C·S_v) δ = F_pred − F is solved
    once per step (no iteration, one engine step per coupling step), and both FMUs step on ramps
    (``fmi2SetRealInputDerivatives``): the body on F → F+ΔF, the engine on the body motion
    predicted for that ramp. Because the stiff direct path F(r, v) is treated implicitly, the
    interface stays stable for coupling steps far beyond the explicit limit; what remains
    explicit is the engine's own (heavy, slow) state response within the step.

    The body response S_r = ∂r(t+H)/∂ΔF, S_v = ∂v(t+H)/∂ΔF is *measured* on the body FMU, not
    approximated: the body is linear and time-invariant (its modal equations are propagated
    exactly for force ramps), so 12 probe steps from a saved and restored FMU state at the start
    give S exactly for every later step, at the cost of 13 body steps once. The approximation from
    the instantaneous interface compliance A = ∂a/∂F (S_v ≈ A·H/2, S_r ≈ A·H²/6) holds only
    while H is short against the periods of the body modes the mounts excite; at 5-10 ms it is
    not (see :func:`body_response` and the table's notes).

The interface starts at the coupled static equilibrium: in initialisation mode the engine's forces
go to the body and the body's mount motion back to the engine, a few times (reading outputs in
initialisation mode makes each FMU solve its static equilibrium for the inputs set so far).

    emc coupling-table        # the table of the user guide (minutes)
"""

from __future__ import annotations

import dataclasses
import pathlib
import sys
import tempfile
import time

import numpy as np
from fmpy import read_model_description

from ..base.errors import UsageError
from ..base.fmu import mount_count, variable_names
from ..base.orders import ORDERS
from ..signals.spectra import order_amplitudes
from .runner import Runner
from .synthesis import HeldForces

ALGORITHMS = ("jacobi", "gauss_seidel", "interface_jacobian")
AXES = 3
COMFORT = [f"steeringWheel.a[{j}]" for j in range(1, AXES + 1)]


def per_mount(pattern: str, mounts: int) -> list[str]:
    """``pattern`` (with ``{i}`` the mount, ``{j}`` the axis) for every mount and axis."""
    return [pattern.format(i=i, j=j) for i in range(1, mounts + 1) for j in range(1, AXES + 1)]


def forces(mounts: int) -> list[str]:
    return per_mount("mount[{i}].F[{j}]", mounts)


def signals(mounts: int) -> list[str]:
    """What a run records: the mount forces and the steering-wheel acceleration."""
    return forces(mounts) + COMFORT


# A mount force beyond this (N) is no longer a car: the coupling has diverged.
FORCE_LIMIT = 1e6


class Diverged(RuntimeError):
    """The coupled run left the physical range: a mount force not finite or beyond
    :data:`FORCE_LIMIT`."""


class Fmu(Runner):
    """One FMU instance on fmpy's low-level API, addressed by variable name: the sweeps'
    :class:`Runner`, started by the coupling master itself."""

    def __init__(self, path, name: str):
        super().__init__(str(path), name)

    def refs(self, names):
        return [self.vr[n] for n in names]

    def start(self, values: dict):
        # No stop time declared: the master may probe a step past t_end (body_response).
        self.slave.setupExperiment(startTime=0.0)
        for name, value in values.items():
            self._set(name, value)

    def errors(self) -> str:
        lines = [line for line in self.log if line.startswith(("[error]", "[fatal]"))]
        return "; ".join(lines[-3:])


def dependency_groups(fmu: Fmu, outputs: list[str],
                      inputs: list[str]) -> tuple[list[list[int]], dict[int, set[int]]]:
    """Inputs (indices into ``inputs``) grouped so that no output depends on two inputs of one
    group, from the dependencies the model description declares: one directional derivative per
    group then gives every column of the group (the engine's mounts are independent, so 3 calls
    instead of 12). Also returns, per output index, the input indices it depends on."""
    index = {fmu.vr[n]: k for k, n in enumerate(inputs)}
    depends: dict[int, set[int]] = {}
    for unknown in fmu.md.outputs:
        if unknown.variable.name in outputs:
            deps = unknown.dependencies
            cols = set(range(len(inputs))) if deps is None else {
                index[d.valueReference] for d in deps if d.valueReference in index}
            depends[outputs.index(unknown.variable.name)] = cols
    groups: list[tuple[list[int], set[int]]] = []
    for col in range(len(inputs)):
        rows = {r for r, cols in depends.items() if col in cols}
        for members, used in groups:
            if not rows & used:
                members.append(col)
                used |= rows
                break
        else:
            groups.append(([col], set(rows)))
    return [members for members, _ in groups], depends


def jacobian(fmu: Fmu, outputs: list[str], inputs: list[str], groups, depends) -> np.ndarray:
    """∂outputs/∂inputs from ``fmi2GetDirectionalDerivative``, one call per input group."""
    out_vr, in_vr = fmu.refs(outputs), fmu.refs(inputs)
    J = np.zeros((len(outputs), len(inputs)))
    for members in groups:
        seed = [1.0] * len(members)
        column = fmu.slave.getDirectionalDerivative(out_vr, [in_vr[c] for c in members], seed)
        for r, value in enumerate(column):
            owners = [c for c in members if c in depends.get(r, set(range(len(inputs))))]
            if owners:
                J[r, owners[0]] = value
    return J


@dataclasses.dataclass
class Run:
    """A coupled (or monolithic) run: signals sampled every ``h`` s up to ``t_end``."""

    h: float
    signals: dict
    wall: float          # s, the stepping loop only
    status: str          # "ok", "diverged at t = … s" or "error at t = … s: …"
    t_reached: float
    # The forces the body was driven with (coupled runs): per output sample interval the ramp's
    # start and end values and the force in effect when the outputs were read (t = 0 first).
    body_forces: HeldForces | None = None

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @classmethod
    def of(cls, signals: dict, h: float) -> "Run":
        """A completed run of ``signals`` sampled every ``h`` s (another host's, for
        :func:`largest_deviation`)."""
        return cls(h=h, signals=signals, wall=0.0, status="ok",
                   t_reached=len(next(iter(signals.values()))) * h)


class CoupledPair:
    """The engine (scene 3) and the body, instantiated and initialised at the coupled static
    equilibrium; :meth:`run` steps them with one of :data:`ALGORITHMS`."""

    def __init__(self, engine_fmu, body_fmu, rpm: float, t_end: float = 1.0,
                 rel_tol: float = 1e-8, cache_dir=None, init_iterations: int = 8,
                 engine_parameters: dict | None = None):
        self.t_end = t_end
        self.engine = Fmu(engine_fmu, "engine")
        self.body = Fmu(body_fmu, "body")
        cache = {} if cache_dir is None else {"chassis.cacheDir": str(cache_dir)}
        self.engine.start({"scene": 3, "rpm": rpm, "solver.relTol": rel_tol, **cache,
                           **(engine_parameters or {})})
        self.body.start(cache)
        e, b = self.engine, self.body
        mounts = mount_count(variable_names(e.md))
        self.names = dict(F=forces(mounts), r=per_mount("mount[{i}].r[{j}]", mounts),
                          v=per_mount("mount[{i}].v[{j}]", mounts),
                          a=per_mount("mount[{i}].a[{j}]", mounts),
                          re=per_mount("mount[{i}].body.r[{j}]", mounts),
                          ve=per_mount("mount[{i}].body.v[{j}]", mounts))
        self.signals = signals(mounts)
        names = self.names
        self.vr = dict(F=e.refs(names["F"]), Fb=b.refs(names["F"]), r=b.refs(names["r"]),
                       v=b.refs(names["v"]), a=b.refs(names["a"]), re=e.refs(names["re"]),
                       ve=e.refs(names["ve"]), sw=b.refs(COMFORT))
        self.n = len(names["F"])
        e.slave.enterInitializationMode()
        b.slave.enterInitializationMode()
        self.init_change = []
        previous = None
        for _ in range(init_iterations):
            F = np.array(e.slave.getReal(self.vr["F"]))
            b.slave.setReal(self.vr["Fb"], list(F))
            r, v = b.slave.getReal(self.vr["r"]), b.slave.getReal(self.vr["v"])
            e.slave.setReal(self.vr["re"], r)
            e.slave.setReal(self.vr["ve"], v)
            if previous is not None:
                self.init_change.append(float(np.max(np.abs(F - previous))))
            previous = F
        # The body rests in static equilibrium under the forces it had when it left
        # initialisation: its state at t = 0.
        self.F_static = previous
        e.slave.exitInitializationMode()
        b.slave.exitInitializationMode()
        self.F = np.array(e.slave.getReal(self.vr["F"]))
        b.slave.setReal(self.vr["Fb"], list(self.F))
        self.k_groups = dependency_groups(e, names["F"], names["re"])
        self.c_groups = dependency_groups(e, names["F"], names["ve"])
        self.a_groups = dependency_groups(b, names["a"], names["F"])

    def close(self):
        self.engine.close()
        self.body.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ----- partial derivatives -----------------------------------------------------------------

    def mount_stiffness(self) -> tuple[np.ndarray, np.ndarray]:
        """K = ∂F/∂r and C = ∂F/∂v of the engine (force on the body w.r.t. the body's motion)."""
        names = self.names
        return (jacobian(self.engine, names["F"], names["re"], *self.k_groups),
                jacobian(self.engine, names["F"], names["ve"], *self.c_groups))

    def interface_compliance(self) -> np.ndarray:
        """A = ∂a/∂F of the body: mount-point accelerations per mount force (inverse interface
        mass)."""
        return jacobian(self.body, self.names["a"], self.names["F"], *self.a_groups)

    def body_response(self, t: float, H: float, probe: float = 1000.0,
                      ramp: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """S_r, S_v: the change of the body's mount displacement and velocity at t+H per unit
        force increment ΔF ramped in over [t, t+H] (``ramp=False``: applied at t and held),
        measured with the body's state saved and restored (exact: the body is linear)."""
        b, vr, n = self.body, self.vr, self.n
        state = b.slave.getFMUstate()
        base = self.F.copy()

        def probe_step(slopes):
            b.slave.setFMUstate(state)
            b.slave.setReal(vr["Fb"], list(base if ramp else base + slopes * H))
            slopes = slopes if ramp else np.zeros(n)
            b.slave.setRealInputDerivatives(vr["Fb"], [1] * n, list(slopes))
            b.slave.doStep(t, H)
            return np.array(b.slave.getReal(vr["r"])), np.array(b.slave.getReal(vr["v"]))

        r0, v0 = probe_step(np.zeros(n))
        S_r, S_v = np.zeros((n, n)), np.zeros((n, n))
        for k in range(n):
            slopes = np.zeros(n)
            slopes[k] = probe / H
            r, v = probe_step(slopes)
            S_r[:, k], S_v[:, k] = (r - r0) / probe, (v - v0) / probe
        b.slave.setFMUstate(state)
        b.slave.freeFMUstate(state)
        b.slave.setReal(vr["Fb"], list(base))
        b.slave.setRealInputDerivatives(vr["Fb"], [1] * n, [0.0] * n)
        return S_r, S_v

    # ----- stepping ----------------------------------------------------------------------------

    def _advance(self, fmu: Fmu, t: float, H: float, m: int, record):
        h = H / m
        for k in range(m):
            fmu.slave.doStep(t + k * h, h)
            if k < m - 1:
                record(k)

    def _exchange(self):
        """The interface consistent at the end of a step: the body's motion into the engine (its
        forces follow at once, direct feedthrough), those forces into the body."""
        e, b, vr = self.engine, self.body, self.vr
        r, v = b.slave.getReal(vr["r"]), b.slave.getReal(vr["v"])
        e.slave.setReal(vr["re"], r)
        e.slave.setReal(vr["ve"], v)
        self.F = np.array(e.slave.getReal(vr["F"]))
        b.slave.setReal(vr["Fb"], list(self.F))
        return np.array(r), np.array(v)

    def run(self, algorithm: str, H: float, h_out: float | None = None,
            jacobian_every: float = 1e-3, extrapolate: bool = True) -> Run:
        """Steps to ``t_end`` with coupling step ``H``; samples the mount forces and the
        steering-wheel acceleration every ``h_out`` (default min(H, 0.5 ms); H/h_out whole: the
        FMUs are then stepped in H/h_out pieces on the same held or ramped inputs, which changes
        nothing but where the outputs are read). For ``interface_jacobian`` the engine's K and C
        are refreshed every step once H reaches ``jacobian_every`` s, else every
        ``jacobian_every`` s of simulated time, and the body motion the engine steps on is
        predicted for a force ramp continuing the previous step's increment (``extrapolate``) or
        for the force held (at 1100 rpm and 1-20 ms their deviations from scene 2 differ by less
        than 0.05 percentage points)."""
        if algorithm not in ALGORITHMS:
            raise ValueError(f"algorithm must be one of {ALGORITHMS}, got {algorithm!r}")
        h_out = min(H, 5e-4) if h_out is None else h_out
        m = int(round(H / h_out))
        if m < 1 or abs(m * h_out - H) > 1e-9 * H:
            raise ValueError(f"the coupling step {H} s is not a whole multiple of the sampling {h_out} s")
        n_steps = int(round(self.t_end / H))
        e, b, vr, nf = self.engine, self.body, self.vr, self.n
        samples = np.full((n_steps * m, len(self.signals)), np.nan)
        ramp_start = np.full((n_steps * m, nf), np.nan)
        ramp_end = np.full((n_steps * m, nf), np.nan)
        read = np.full((n_steps * m + 1, nf), np.nan)
        read[0] = self.F
        fractions = np.arange(m + 1)[:, None] / m
        zeros = [0.0] * nf
        ones = [1] * nf
        r = np.array(b.slave.getReal(vr["r"]))
        v = np.array(b.slave.getReal(vr["v"]))
        if algorithm == "interface_jacobian":
            S_r, S_v = self.body_response(0.0, H)
            refresh = max(1, int(round(jacobian_every / H)))
            dF = np.zeros(nf)
            I = np.eye(nf)
        row = 0
        t_reached = 0.0
        status = "ok"
        begin = time.perf_counter()
        try:
            for n in range(n_steps):
                t = n * H
                base = row

                def rec_engine(k):
                    samples[base + k, :nf] = e.slave.getReal(vr["F"])

                def rec_body(k):
                    samples[base + k, nf:] = b.slave.getReal(vr["sw"])

                if algorithm == "jacobi":
                    e.slave.setRealInputDerivatives(vr["re"], ones, zeros)
                    e.slave.setRealInputDerivatives(vr["ve"], ones, zeros)
                    b.slave.setRealInputDerivatives(vr["Fb"], ones, zeros)
                    self._advance(e, t, H, m, rec_engine)
                    self._advance(b, t, H, m, rec_body)
                    increment = np.zeros(nf)
                elif algorithm == "gauss_seidel":
                    e.slave.setRealInputDerivatives(vr["re"], ones, zeros)
                    e.slave.setRealInputDerivatives(vr["ve"], ones, zeros)
                    self._advance(e, t, H, m, rec_engine)
                    F_end = np.array(e.slave.getReal(vr["F"]))
                    increment = F_end - self.F
                    b.slave.setRealInputDerivatives(vr["Fb"], ones, list(increment / H))
                    self._advance(b, t, H, m, rec_body)
                else:
                    # The body motion for the guessed ramp (exact for that ramp: the body is
                    # linear); the engine steps on it, the correction comes at the end.
                    state = b.slave.getFMUstate()
                    b.slave.setRealInputDerivatives(vr["Fb"], ones, list(dF / H))
                    b.slave.doStep(t, H)
                    r_pred = np.array(b.slave.getReal(vr["r"]))
                    v_pred = np.array(b.slave.getReal(vr["v"]))
                    b.slave.setFMUstate(state)
                    b.slave.freeFMUstate(state)
                    e.slave.setReal(vr["re"], list(r))
                    e.slave.setReal(vr["ve"], list(v))
                    e.slave.setRealInputDerivatives(vr["re"], ones, list((r_pred - r) / H))
                    e.slave.setRealInputDerivatives(vr["ve"], ones, list((v_pred - v) / H))
                    self._advance(e, t, H, m, rec_engine)
                    F_pred = np.array(e.slave.getReal(vr["F"]))
                    if n % refresh == 0:
                        K, C = self.mount_stiffness()
                        M = I - K @ S_r - C @ S_v
                    delta = np.linalg.solve(M, F_pred - self.F - dF)
                    dF = dF + delta
                    dF_next = dF if extrapolate else np.zeros(nf)
                    b.slave.setReal(vr["Fb"], list(self.F))
                    b.slave.setRealInputDerivatives(vr["Fb"], ones, list(dF / H))
                    self._advance(b, t, H, m, rec_body)
                    increment = dF
                    dF = dF_next
                ramp = self.F + fractions * increment  # the body's input over the step
                ramp_start[base:base + m] = ramp[:-1]
                ramp_end[base:base + m] = ramp[1:]
                read[base + 1:base + m] = ramp[1:-1]
                r, v = self._exchange()
                read[base + m] = self.F
                row += m
                samples[row - 1, :nf] = self.F
                samples[row - 1, nf:] = b.slave.getReal(vr["sw"])
                t_reached = (n + 1) * H
                last = samples[base:row]
                if not np.all(np.isfinite(last)) or np.max(np.abs(last[:, :nf])) > FORCE_LIMIT:
                    raise Diverged(f"diverged at t = {t_reached:.4g} s")
        except Diverged as error:
            status = str(error)
        except Exception as error:  # noqa: BLE001 - fmpy raises FMICallException for error/discard
            cause = e.errors() or b.errors() or str(error)
            status = f"error at t = {t_reached:.4g} s: {cause}"
        wall = time.perf_counter() - begin
        done = int(round(t_reached / h_out))
        held = HeldForces(dt=h_out, start=ramp_start[:done], end=ramp_end[:done],
                          read=read[:done + 1])
        return Run(h=h_out, signals=dict(zip(self.signals, samples.T)), wall=wall, status=status,
                   t_reached=t_reached, body_forces=held)


def coupled(engine_fmu, body_fmu, rpm: float, algorithm: str, H: float, t_end: float = 1.0,
            rel_tol: float = 1e-8, cache_dir=None, h_out: float | None = None,
            engine_parameters: dict | None = None) -> Run:
    """One coupled run from the coupled static equilibrium (both FMUs freed afterwards).
    ``engine_parameters``: further start values of the engine (e.g. mount stiffness scales)."""
    with CoupledPair(engine_fmu, body_fmu, rpm, t_end, rel_tol, cache_dir,
                     engine_parameters=engine_parameters) as pair:
        return pair.run(algorithm, H, h_out)


def monolithic(engine_fmu, rpm: float, h: float = 1e-4, t_end: float = 1.0,
               rel_tol: float = 1e-8, cache_dir=None, engine_parameters: dict | None = None) -> Run:
    """Scene 2 (engine on the body inside one FMU) stepped every ``h`` on the same low-level
    loop, sampling the same signals."""
    fmu = Fmu(engine_fmu, "scene2")
    try:
        cache = {} if cache_dir is None else {"chassis.cacheDir": str(cache_dir)}
        fmu.start({"scene": 2, "rpm": rpm, "solver.relTol": rel_tol, **cache,
                   **(engine_parameters or {})})
        fmu.slave.enterInitializationMode()
        fmu.slave.exitInitializationMode()
        recorded = signals(mount_count(variable_names(fmu.md)))
        vr = fmu.refs(recorded)
        n = int(round(t_end / h))
        samples = np.empty((n, len(recorded)))
        begin = time.perf_counter()
        for k in range(n):
            fmu.slave.doStep(k * h, h)
            samples[k] = fmu.slave.getReal(vr)
        wall = time.perf_counter() - begin
    finally:
        fmu.close()
    return Run(h=h, signals=dict(zip(recorded, samples.T)), wall=wall, status="ok", t_reached=t_end)


def largest_deviation(reference: Run, run: Run, rpm: float, revolutions: int = 8,
                      floor: str = "signal") -> tuple[float, str]:
    """Largest relative deviation of the order amplitudes of ``run`` from ``reference`` over the
    mount forces and the steering-wheel acceleration, orders 0.5..6, and where it occurs. Orders
    below 1 % of the largest are left out: the largest of each signal (``floor="signal"``), or
    the largest of its group, mount forces or steering wheel (``floor="group"``: a force
    component that is nearly zero by symmetry then does not count with its own scale). The
    reference is decimated to the run's sampling."""
    step = int(round(run.h / reference.h))

    def orders_of(x) -> np.ndarray:
        return np.array(list(order_amplitudes(x, revolutions, ORDERS, 60.0 / rpm / run.h).values()))

    names = list(run.signals)
    force_names = [n for n in names if n not in COMFORT]
    ref = {n: orders_of(reference.signals[n][step - 1::step]) for n in names}
    got = {n: orders_of(run.signals[n]) for n in names}
    group = {n: max(ref[m].max() for m in (force_names if n in force_names else COMFORT))
             for n in names}
    worst, where = 0.0, ""
    for name in names:
        scale = ref[name].max() if floor == "signal" else group[name]
        for o, x, y in zip(ORDERS, ref[name], got[name]):
            if x < 0.01 * scale:
                continue
            rel = abs(y - x) / x if np.isfinite(y) else np.inf
            if rel > worst or not where:
                worst, where = rel, f"{name} order {o:g}"
    return worst, where


def growth(reference: Run, run: Run, rpm: float, revolutions: int = 8) -> float:
    """Largest ratio over the mount forces of the peak-to-peak value in the last ``revolutions``
    (before the end, or before the run failed) to scene 2's over the same time: an interface
    oscillation that grows (or settles on a large limit cycle on the stiffening mount curves
    instead of reaching the force limit) shows here."""
    step = int(round(run.h / reference.h))
    end = int(round(run.t_reached / run.h))
    n = min(end, int(round(revolutions * 60.0 / rpm / run.h)))
    if n < 2:
        return float("nan")
    return max(np.ptp(run.signals[f][end - n:end])
               / np.ptp(reference.signals[f][step - 1::step][end - n:end])
               for f in run.signals if f not in COMFORT)


# ----- the table ---------------------------------------------------------------------------------

STEPS = (1e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2, 5e-2)
# An interface oscillation this many times scene 2's peak-to-peak force is called unstable.
GROWTH_LIMIT = 5.0


def interface_numbers(engine_fmu, body_fmu, rpm: float, cache_dir, steps=STEPS,
                      engine_parameters=None, t_end: float = 1.0) -> dict:
    """Mount stiffness and damping, interface compliance and the explicit-coupling estimate at
    the coupled static equilibrium.

    Explicit exchange (Jacobi; Gauss-Seidel alike for the body's own feedback) of a mount of
    tangent stiffness k and damping c on a body of mobility λ (1/kg), the force held over H and
    the body integrated exactly: x' = x + H v − λH²/2 (k x + c v), v' = v − λH (k x + c v). The
    determinant of that map is 1 − λcH + λkH²/2, so per step the amplitude grows by
    ≈ (λH/2)(kH/2 − c): unstable for H > 2c/k whatever the mass, and the growth over a time t is
    exp(t λ (kH/4 − c/2)). Which λ: the body's response over the step to a held force,
    λ_eff(H) = λmax(P_v(H))/H with P_v measured on the body (λ_eff → λmax(A) for small H; it
    falls once H passes the periods of the body modes at the mounts)."""
    with CoupledPair(engine_fmu, body_fmu, rpm, 0.01, cache_dir=cache_dir,
                     engine_parameters=engine_parameters) as pair:
        K, C = pair.mount_stiffness()
        A = pair.interface_compliance()
        S = {H: pair.body_response(0.0, H) for H in (1e-3, 1e-2)}
        held = {H: pair.body_response(0.0, H, ramp=False)[1] for H in steps}
    diag_k, diag_c = -np.diag(K), -np.diag(C)
    axis = int(np.argmax(diag_k / diag_c))
    k_axis, c_axis = float(diag_k[axis]), float(diag_c[axis])
    lam_eff = {H: float(np.max(np.linalg.eigvalsh((P + P.T) / 2))) / H for H, P in held.items()}
    predicted = {H: float(np.exp(t_end * lam * (k_axis * H / 4 - c_axis / 2)))
                 for H, lam in lam_eff.items()}
    # Interface mode of the body on the mounts (engine held: it is 100 times heavier).
    w2, modes = np.linalg.eig(-A @ K)
    k = int(np.argmax(w2.real))
    omega = float(np.sqrt(w2[k].real))
    mode = modes[:, k].real
    # Damping of that mode: 2 ζ ω = (mode' A⁻¹ (−A C) mode)/(mode' A⁻¹ mode), A symmetric.
    Ainv = np.linalg.inv(A)
    two_zeta_omega = float(mode @ Ainv @ (-A @ C) @ mode / (mode @ Ainv @ mode))
    stiff = [float(np.max(np.linalg.eigvalsh(-(K[3 * i:3 * i + 3, 3 * i:3 * i + 3]
                                              + K[3 * i:3 * i + 3, 3 * i:3 * i + 3].T) / 2)))
             for i in range(K.shape[0] // AXES)]
    approx = {H: (float(np.linalg.norm(S[H][0] - A * H * H / 6) / np.linalg.norm(S[H][0])),
                  float(np.linalg.norm(S[H][1] - A * H / 2) / np.linalg.norm(S[H][1])))
              for H in S}
    return dict(k_max=max(stiff), lambda_A=float(np.max(np.linalg.eigvalsh((A + A.T) / 2))),
                omega=omega, zeta=two_zeta_omega / (2 * omega), approx=approx,
                explicit_limit=2 * c_axis / k_axis, lambda_eff=lam_eff, predicted_growth=predicted)


def table(engine_fmu, body_fmu, rpms=(1100.0, 2000.0), steps=STEPS, algorithms=ALGORITHMS,
          t_end: float = 1.0, cache_dir=None, out=sys.stdout,
          engine_parameters: dict | None = None) -> list[dict]:
    cache_dir = cache_dir or pathlib.Path(tempfile.gettempdir()) / "emc-coupling-cache"
    rows = []
    for rpm in rpms:
        fine = monolithic(engine_fmu, rpm, 1e-4, t_end, cache_dir=cache_dir,
                          engine_parameters=engine_parameters)
        coarse = monolithic(engine_fmu, rpm, 5e-4, t_end, cache_dir=cache_dir,
                            engine_parameters=engine_parameters)
        numbers = interface_numbers(engine_fmu, body_fmu, rpm, cache_dir, steps,
                                    engine_parameters, t_end)
        print(f"\n{rpm:g} rpm: scene 2 wall time {fine.wall:.2f} s at 0.1 ms steps, "
              f"{coarse.wall:.2f} s at 0.5 ms (fmpy low-level loop, {t_end:g} s simulated)", file=out)
        print(f"  largest mount tangent stiffness {numbers['k_max'] / 1e3:.1f} N/mm, "
              f"λmax(A) {numbers['lambda_A']:.4g} 1/kg, interface mode ω = sqrt(λmax(−A K)) "
              f"= {numbers['omega']:.4g} rad/s ({numbers['omega'] / 2 / np.pi:.1f} Hz), "
              f"ζ = {numbers['zeta']:.3f}; explicit limit 4ζ/ω = {4 * numbers['zeta'] / numbers['omega'] * 1e3:.3g} ms, "
              f"2/ω = {2 / numbers['omega'] * 1e3:.3g} ms; explicit limit 2c/k = "
              f"{numbers['explicit_limit'] * 1e3:.3g} ms", file=out)
        for H, (er, ev) in numbers["approx"].items():
            print(f"  body ramp response vs A·H²/6, A·H/2 at H = {H * 1e3:g} ms: "
                  f"{er * 100:.1f} %, {ev * 100:.1f} % off", file=out)
        print("  explicit exchange, predicted growth over the run exp(t λ_eff (kH/4 − c/2)): " + ", ".join(
            f"{H * 1e3:g} ms: λ_eff {numbers['lambda_eff'][H]:.3g} 1/kg, ×{numbers['predicted_growth'][H]:.3g}"
            for H in steps), file=out)
        print(f"  {'H (ms)':>7} {'algorithm':<19} {'status':<12} {'growth':>7} {'dev (%)':>9} "
              f"{'dev group (%)':>13} {'where (group floor)':<28} {'wall (s)':>8} {'/scene 2':>8}",
              file=out)
        for H in steps:
            ref = fine if H < 5e-4 else coarse
            for algorithm in algorithms:
                run = coupled(engine_fmu, body_fmu, rpm, algorithm, H, t_end, cache_dir=cache_dir,
                              engine_parameters=engine_parameters)
                dev = dev_group = grow = float("nan")
                where = ""
                status = run.status
                if run.ok:
                    dev, _ = largest_deviation(fine, run, rpm)
                    dev_group, where = largest_deviation(fine, run, rpm, floor="group")
                    grow = growth(fine, run, rpm)
                    if grow > GROWTH_LIMIT:
                        status = "unstable"
                else:
                    grow = growth(fine, run, rpm)
                    kind = "diverged" if run.status.startswith("diverged") else "error"
                    status = f"{kind}@{run.t_reached:.2f}s"
                row = dict(rpm=rpm, H=H, algorithm=algorithm, status=status, detail=run.status,
                           growth=grow, deviation=dev, deviation_group=dev_group, where=where,
                           wall=run.wall, wall_ratio=run.wall / ref.wall, **numbers)
                rows.append(row)
                print(f"  {H * 1e3:7.1f} {algorithm:<19} {status:<12} {grow:7.3g} {dev * 100:9.3g} "
                      f"{dev_group * 100:13.3g} {where:<28} {run.wall:8.2f} {run.wall / ref.wall:8.2f}",
                      file=out, flush=True)
    return rows


def cmd_coupling_table(args) -> int:
    """``emc coupling-table``: the stability and accuracy table of the coupling algorithms."""
    algorithms = args.algorithms or list(ALGORITHMS)
    unknown = [a for a in algorithms if a not in ALGORITHMS]
    if unknown:
        raise UsageError(f"--algorithms {' '.join(unknown)}: none of {', '.join(ALGORITHMS)}")
    steps = args.steps or [h * 1e3 for h in STEPS]
    mounts = mount_count(variable_names(read_model_description(args.fmu)))
    scale = {f"mount[{i}].stiffnessScale": args.stiffness_scale for i in range(1, mounts + 1)}
    table(args.fmu, args.body_fmu, args.rpm, [s * 1e-3 for s in steps], algorithms,
          args.t_end, engine_parameters=scale if args.stiffness_scale != 1.0 else None)
    return 0
