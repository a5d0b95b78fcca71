"""Each transfer path's contribution to a body point's acceleration in the time domain.

The body is linear and only the mount forces act on it, so a body point's acceleration is the sum
over the paths p (mount i, direction j) of the body's response to ``F_p(t)`` alone. For a run-up,
or any window that is not a periodic steady state, a path's contribution is that response, not
the product of its force's order with a transfer function: the lightly damped modes carry the
past. It is synthesised here from the modal data the FMU exports (:class:`emc.running.modal.Body`): each
mode ``eta'' + 2 zeta omega eta' + omega^2 eta = q(t)`` is propagated exactly over each sampling
step for a force that varies linearly between its samples (first-order hold, the exact
discretisation of Van Loan's augmented exponential), and ``a = sum_k phi_out,k eta_k''``.

The modal state at the first sample is each path's own part of the body's state there: for a
start from the static equilibrium, the static deflection under that path's force; for a start on
the periodic steady state, that path's periodic response, from the harmonics of one working cycle
of its force (:func:`periodic_state`).

The forces a master applies to the body FMU are such ramps (:class:`HeldForces`): there the
synthesis is exact. A force sampled from a continuous signal (the engine in the body, scene 2)
is interpolated: a hold between its samples would reach the modes attenuated by ``sinc²(f dt)``,
``1 − (π f dt)²/3`` (2e-3 at 180 Hz and 0.2 ms), so :meth:`HeldForces.from_samples` first
interpolates it ``refine`` times finer with a cubic spline.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.linalg import expm
from scipy.signal import lfilter

from .modal import Body


def hold_discretisation(omega: float, zeta: float, dt: float):
    """Mode (omega rad/s, zeta) with a first-order-hold force over steps of ``dt``:
    ``x_{n+1} = Phi x_n + G0 q_n + G1 q_{n+1}`` with x = (eta, eta'), exactly."""
    a = np.array([[0.0, 1.0], [-omega**2, -2.0 * zeta * omega]])
    m = np.zeros((4, 4))
    m[:2, :2] = a
    m[1, 2] = 1.0          # B
    m[2, 3] = 1.0 / dt     # the force's slope over the step
    e = expm(m * dt)
    phi, g_hold, g_ramp = e[:2, :2], e[:2, 2], e[:2, 3]
    return phi, g_hold - g_ramp, g_ramp


def state_filters(omega: float, zeta: float, dt: float):
    """The recursion of :func:`hold_discretisation` as two filters onto ``C x_n`` with
    ``C = (−omega², −2 zeta omega)`` (the modal acceleration less the force): one from the force
    at the start of each step, one from the force at its end (both strictly proper: ``x_n``
    depends on the steps before n); and (Phi, C) for the free response."""
    phi, g0, g1 = hold_discretisation(omega, zeta, dt)
    c = np.array([-omega**2, -2.0 * zeta * omega])
    # c (zI − Phi)^-1 g = (z c·g − c adj(Phi) g) / det(zI − Phi), adj(zI − Phi) = z I − adj(Phi).
    adj_phi = np.array([[phi[1, 1], -phi[0, 1]], [-phi[1, 0], phi[0, 0]]])
    den = np.array([1.0, -np.trace(phi), np.linalg.det(phi)])
    start, end = (np.array([0.0, c @ g, -(c @ adj_phi @ g)]) for g in (g0, g1))
    return start, end, den, phi, c


def free_acceleration(phi: np.ndarray, c: np.ndarray, w0: np.ndarray, n: int,
                      stride: int = 1) -> np.ndarray:
    """``C Psi^k w0`` for k = 0..n−1 with ``Psi = Phi^stride``; ``w0`` of shape (2, m): (n, m).

    By Cayley-Hamilton the sequence obeys ``s_k = tr(Psi) s_{k-1} − det(Psi) s_{k-2}``: the
    impulse response of a two-pole filter started from ``s_0, s_1`` (no eigenvectors, which a
    critically damped mode does not have)."""
    psi = np.linalg.matrix_power(phi, stride)
    den = np.array([1.0, -np.trace(psi), np.linalg.det(psi)])
    s0, s1 = c @ w0, c @ psi @ w0
    impulse = np.zeros(n)
    impulse[0] = 1.0
    # b0 = s_0, b1 = s_1 − tr(Psi) s_0.
    return np.column_stack([lfilter([a, b + den[1] * a], den, impulse) for a, b in zip(s0, s1)])


def periodic_state(body: Body, cycle: np.ndarray, period: float) -> np.ndarray:
    """Modal state (eta, eta') at the start of the cycle, per mode and path: (2, modes, paths),
    per unit mode-shape entry (the path's modal force is ``phi_pk F_p``), of the periodic
    response to the force ``cycle`` (samples × paths, one period from t = 0 on, equally
    spaced)."""
    n = len(cycle)
    spectrum = np.fft.rfft(cycle, axis=0) / n                          # (harmonics, paths)
    w = 2.0 * np.pi * np.arange(len(spectrum)) / period
    weight = np.full(len(spectrum), 2.0)
    weight[0] = 1.0
    if n % 2 == 0:
        weight[-1] = 1.0
    r = 1.0 / (body.omega[None, :] ** 2 - w[:, None] ** 2
               + 2j * body.zeta[None, :] * body.omega[None, :] * w[:, None])  # (harmonics, modes)
    terms = weight[:, None, None] * r[:, :, None] * spectrum[:, None, :]    # (h, modes, paths)
    eta = terms.sum(axis=0).real
    rate = (1j * w[:, None, None] * terms).sum(axis=0).real
    return np.stack([eta, rate])


def static_state(body: Body, force: np.ndarray) -> np.ndarray:
    """Modal state at rest under the force ``force`` (per path), per unit mode-shape entry:
    (2, modes, paths)."""
    eta = np.asarray(force, float)[None, :] / body.omega[:, None] ** 2
    return np.stack([eta, np.zeros_like(eta)])


@dataclasses.dataclass
class HeldForces:
    """Forces that vary linearly over each step of ``dt``: per step k (from t = k dt) the value
    at its start ``start[k]`` and at its end ``end[k]`` (a jump between steps is allowed), and
    ``read[k]`` the force in effect when the response at t = k dt was read (the acceleration
    follows the force without delay). Shapes (steps, inputs) and (steps + 1, inputs)."""

    dt: float
    start: np.ndarray
    end: np.ndarray
    read: np.ndarray
    every: int = 1  # the responses are returned every this many steps

    @classmethod
    def from_samples(cls, forces: np.ndarray, dt: float, refine: int = 4) -> "HeldForces":
        """Forces sampled every ``dt`` from t = 0 (row 0 at the start) of a continuous signal,
        interpolated ``refine`` times finer by a cubic spline (the hold then attenuates the
        order at f by ``1 − (π f dt / refine)² / 3`` instead of ``1 − (π f dt)² / 3``)."""
        forces = np.asarray(forces, float)
        n = len(forces)
        if refine > 1:
            times = np.arange((n - 1) * refine + 1) * (dt / refine)
            forces = CubicSpline(np.arange(n) * dt, forces, axis=0)(times)
        return cls(dt=dt / max(refine, 1), start=forces[:-1], end=forces[1:], read=forces,
                   every=max(refine, 1))


def path_responses(body: Body, forces: HeldForces, outputs: list[tuple[str, int]],
                   inputs: list[tuple[str, int]], initial: np.ndarray | None = None
                   ) -> np.ndarray:
    """Acceleration of each output (point, dof 0..2) caused by each input force alone, at
    t = 0, every·dt, 2·every·dt, … (``forces.every``): (samples, outputs, inputs), m/s².

    ``initial``: the modal state at t = 0 per unit mode-shape entry (2, modes, inputs) from
    :func:`static_state` or :func:`periodic_state` (None: the body at rest, undeformed). The sum
    over the inputs is the body's response to all forces together."""
    steps, paths = forces.start.shape
    if paths != len(inputs):
        raise ValueError(f"{paths} force columns for {len(inputs)} inputs")
    # The filters run along contiguous rows; one more (zero) step gives C x at the last time.
    start = np.zeros((paths, steps + 1))
    end = np.zeros((paths, steps + 1))
    start[:, :steps], end[:, :steps] = forces.start.T, forces.end.T
    every = forces.every
    read = forces.read[::every]
    n = len(read)
    phi_in = np.column_stack([body.point(p)[:, d] for p, d in inputs])     # (modes, inputs)
    phi_out = np.column_stack([body.point(p)[:, d] for p, d in outputs])   # (modes, outputs)
    out = np.zeros((n, len(outputs), paths))
    for k, (omega, zeta) in enumerate(zip(body.omega, body.zeta)):
        from_start, from_end, den, phi, c = state_filters(float(omega), float(zeta), forces.dt)
        # Per unit mode-shape entry: the modal force of input p is phi_in[k, p] F_p.
        forced = lfilter(from_start, den, start, axis=1) + lfilter(from_end, den, end, axis=1)
        # forced[:, n] = C x_n (n = 0..steps) from the steps before n.
        y = forced[:, ::every].T + read
        if initial is not None:
            y = y + free_acceleration(phi, c, initial[:, k, :], n, every)
        out += y[:, None, :] * (phi_out[k][:, None] * phi_in[k][None, :])[None, :, :]
    return out
