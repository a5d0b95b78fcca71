//! Cylinder gas pressure over the 720° cycle (paper §4.2, DESIGN §4.1).
//!
//! Single-zone model: between inlet valve closing and exhaust valve opening the first law
//! `dp/dθ = (κ−1)/V · dQ/dθ − κ p/V · dV/dθ` with a (multi-stage) Wiebe heat release
//! `x = 1 − exp(−6.908 ((θ − θ_soc)/Δθ)^(m+1))` and a polytropic exponent that moves linearly from
//! compression to expansion value. It is integrated once per operating point (idle, full load) on
//! a 0.05° grid; outside the closed part the pressure blends smoothly back to the charge pressure
//! (the valve events decided in degrees and blended C¹). The load parameter interpolates linearly
//! between the idle and full-load curves. Evaluation uses quintic Hermite interpolation (value,
//! slope and curvature at every knot), so the pressure is C² in the crank angle.

use serde::{Deserialize, Serialize};

/// One Wiebe combustion stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WiebeStage {
    /// Fraction of the cycle's heat released by this stage.
    pub fraction: f64,
    /// Start of combustion (deg after firing TDC).
    pub start_deg: f64,
    /// Combustion duration (deg).
    pub duration_deg: f64,
    /// Wiebe shape exponent m.
    pub shape: f64,
}

/// Charge and heat release at one load point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CombustionPoint {
    /// Cylinder pressure at inlet valve closing (Pa).
    pub pressure_ivc: f64,
    /// Heat released per cylinder and cycle (J).
    pub heat: f64,
    /// The combustion stages (premixed, diffusion, …); their fractions add up to 1.
    pub stages: Vec<WiebeStage>,
}

/// Heat transfer from the gas to the combustion-chamber walls by Woschni's correlation
/// (G. Woschni, SAE 670931, 1967; as given by J. B. Heywood, Internal Combustion Engine
/// Fundamentals, 1988, eq. 12.19):
/// `h = 3.26 B^-0.2 p^0.8 T^-0.55 w^0.8` (W/m²K; bore B in m, p in kPa, T in K) with the gas
/// velocity `w = C1 c_m + C2 V_d T_ivc / (p_ivc V_ivc) (p − p_motored)`, C1 = 2.28, C2 = 0 during
/// compression and 3.24e-3 m/(s K) from the start of combustion on. The gas temperature follows
/// from the ideal gas law with the mass trapped at IVC.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WallHeatTransfer {
    /// Mean wall temperature of head, piston and liner (K). Heywood §12.6 gives 400–600 K for
    /// the combustion-chamber surfaces of a warm engine; 450 K is a liner-weighted mean.
    pub wall_temperature: f64,
    /// Charge temperature at inlet valve closing (K): intercooled charge heated by the walls
    /// and the residual gas.
    pub charge_temperature: f64,
    /// Engine speed at which the heat loss per crank angle is evaluated (rpm): the curves are
    /// functions of the crank angle, computed once; the loss per degree falls with the speed
    /// (less time per degree), so it is taken in the middle of the analysed range.
    pub reference_speed_rpm: f64,
}

impl Default for WallHeatTransfer {
    fn default() -> Self {
        Self {
            wall_temperature: 450.0,
            charge_temperature: 340.0,
            reference_speed_rpm: 1500.0,
        }
    }
}

/// Single-zone Wiebe model parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct WiebeModel {
    /// Geometric compression ratio.
    pub compression_ratio: f64,
    /// Polytropic exponent of the compression.
    pub kappa_compression: f64,
    /// Polytropic exponent of the expansion (the exponent moves linearly between the two).
    pub kappa_expansion: f64,
    /// Inlet valve closing (deg after firing TDC, negative).
    pub ivc_deg: f64,
    /// Exhaust valve opening (deg after firing TDC).
    pub evo_deg: f64,
    /// Crank angle over which the pressure blows down to the charge pressure after EVO (deg).
    pub blowdown_deg: f64,
    /// Charge and heat release at idle (load 0).
    pub idle: CombustionPoint,
    /// Charge and heat release at full load (load 1).
    pub full_load: CombustionPoint,
    /// Wall heat loss during the closed cycle; `None` = adiabatic walls (the heat released
    /// then all goes into the gas: an indicated efficiency far above a real engine's).
    pub wall_heat: Option<WallHeatTransfer>,
}

impl Default for WiebeModel {
    fn default() -> Self {
        Self {
            compression_ratio: 18.5,
            kappa_compression: 1.36,
            kappa_expansion: 1.30,
            ivc_deg: -150.0,
            evo_deg: 130.0,
            blowdown_deg: 60.0,
            idle: CombustionPoint {
                pressure_ivc: 1.0e5,
                heat: 220.0,
                stages: vec![WiebeStage {
                    fraction: 1.0,
                    start_deg: -6.0,
                    duration_deg: 30.0,
                    shape: 2.0,
                }],
            },
            full_load: CombustionPoint {
                pressure_ivc: 2.0e5,
                heat: 1500.0,
                stages: vec![
                    WiebeStage {
                        fraction: 0.08,
                        start_deg: -6.0,
                        duration_deg: 8.0,
                        shape: 2.0,
                    },
                    WiebeStage {
                        fraction: 0.92,
                        start_deg: -6.0,
                        duration_deg: 60.0,
                        shape: 0.9,
                    },
                ],
            },
            wall_heat: Some(WallHeatTransfer::default()),
        }
    }
}

/// User-supplied pressure over the cycle (absolute Pa at deg after firing TDC, covering 720°).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PressureTable {
    /// Crank angles (deg after firing TDC), ascending.
    pub angle_deg: Vec<f64>,
    /// Absolute pressure at each angle (Pa).
    pub pressure: Vec<f64>,
}

/// Source of the cylinder pressure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum GasModel {
    /// The single-zone Wiebe combustion model, integrated per load point.
    Wiebe(WiebeModel),
    /// A user-supplied pressure curve (the load parameter does not change it).
    Table(PressureTable),
}

impl Default for GasModel {
    fn default() -> Self {
        GasModel::Wiebe(WiebeModel::default())
    }
}

/// Cylinder geometry needed by the pressure model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderGeometry {
    /// Cylinder bore (m).
    pub bore: f64,
    /// Crank radius (m).
    pub crank_radius: f64,
    /// Conrod length (m).
    pub conrod: f64,
}

impl CylinderGeometry {
    /// Piston crown area `π bore² / 4` (m²).
    pub fn piston_area(&self) -> f64 {
        std::f64::consts::PI * 0.25 * self.bore * self.bore
    }

    /// Swept volume of one cylinder (m³).
    pub fn displacement(&self) -> f64 {
        self.piston_area() * 2.0 * self.crank_radius
    }

    /// Gas-side wall area at volume `v`: head and piston crown (flat, one bore each) and the
    /// liner over the height `v / A_p` of a cylinder of that volume.
    fn wall_area(&self, v: f64) -> f64 {
        let a = self.piston_area();
        2.0 * a + std::f64::consts::PI * self.bore * v / a
    }

    /// Cylinder volume at crank angle `theta` (rad after TDC) for a compression ratio.
    fn volume(&self, theta: f64, compression_ratio: f64) -> (f64, f64) {
        let (r, l) = (self.crank_radius, self.conrod);
        let a = self.piston_area();
        let displacement = a * 2.0 * r;
        let clearance = displacement / (compression_ratio - 1.0);
        let (s, s1, _) = super::parts::slider_crank(theta, r, l);
        (clearance + a * (r + l - s), -a * s1)
    }
}

/// Table spacing of the pressure curves. Between knots the curve is a quintic Hermite
/// interpolant of the values and of their first and second derivatives (fourth-order central
/// differences on the grid), so it is C²: the integrator's error estimate meets no jump of the
/// second derivative at every knot. (With a C¹ cubic table on a 0.25° grid the error stalled
/// near 1e-3 whatever the tolerance; at 0.05° the table's share of the remaining ~1e-4 floor is
/// below what `examples/accuracy_cost.rs` resolves: C¹ and C² give the same floor.)
const GRID_DEG: f64 = 0.05;

/// Wiebe pressure tables kept per process (two per engine configuration, or two per cylinder
/// with a cylinder-to-cylinder spread).
const WIEBE_MEMO_SIZE: usize = 32;

/// Crank angle over which the charge pressure blends into the compression before IVC.
const IVC_LEAD_IN_DEG: f64 = 10.0;

/// Tabulated cylinder pressure over one cycle, ready for fast C² evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct PressureCurve {
    /// Per knot at angles −360° + k·GRID_DEG (k = 0..14400, periodic): the pressure and its first
    /// and second derivatives per grid step (units of pressure per knot spacing). Kept together
    /// so one evaluation reads two adjacent entries: a cycle's table is 350 kB, and three
    /// cylinders' tables as separate arrays made every lookup six cache misses.
    knots: Vec<[f64; 3]>,
}

/// Knots per degree of crank angle.
const KNOTS_PER_DEG: f64 = 1.0 / GRID_DEG;

impl PressureCurve {
    /// Absolute pressure at cycle angle `theta` (rad after firing TDC, any value; period 4π).
    pub fn pressure(&self, theta: f64) -> f64 {
        let n = self.knots.len();
        let u = (theta.to_degrees() + 360.0) * KNOTS_PER_DEG;
        let period = n as f64;
        let u = u - period * (u / period).floor();
        let i = (u as usize).min(n - 1);
        let t = u - i as f64;
        let j = if i + 1 == n { 0 } else { i + 1 };
        let (t2, t3) = (t * t, t * t * t);
        let (t4, t5) = (t3 * t, t3 * t2);
        // Quintic Hermite basis: value, slope and curvature at each end.
        let h_p1 = 10.0 * t3 - 15.0 * t4 + 6.0 * t5;
        let h_p0 = 1.0 - h_p1;
        let h_d0 = t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5;
        let h_d1 = -4.0 * t3 + 7.0 * t4 - 3.0 * t5;
        let h_s0 = 0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5;
        let h_s1 = 0.5 * t3 - t4 + 0.5 * t5;
        let [p0, d0, s0] = self.knots[i];
        let [p1, d1, s1] = self.knots[j];
        h_p0 * p0 + h_p1 * p1 + h_d0 * d0 + h_d1 * d1 + h_s0 * s0 + h_s1 * s1
    }

    /// Indicated work per cycle `∮ p dV` of one cylinder (J), gross of pumping: the trapezoid
    /// rule over the table's grid (exact to the grid's resolution).
    pub fn indicated_work(&self, geometry: &CylinderGeometry, compression_ratio: f64) -> f64 {
        let step = GRID_DEG.to_radians();
        self.knots
            .iter()
            .enumerate()
            .map(|(k, knot)| {
                let theta = (-360.0 + k as f64 * GRID_DEG).to_radians();
                let (_, dv) = geometry.volume(theta, compression_ratio);
                knot[0] * dv * step
            })
            .sum()
    }

    /// Whether every value and slope of the table is finite.
    pub fn is_finite(&self) -> bool {
        self.knots.iter().flatten().all(|x| x.is_finite())
    }

    /// Peak pressure over the cycle (Pa).
    pub fn peak(&self) -> f64 {
        self.knots.iter().map(|k| k[0]).fold(f64::MIN, f64::max)
    }

    fn from_samples(values: Vec<f64>) -> Self {
        let n = values.len();
        let at = |i: usize, k: isize| values[(i as isize + k).rem_euclid(n as isize) as usize];
        // Fourth-order central differences on the periodic grid.
        let knots = (0..n)
            .map(|i| {
                let first = (-at(i, 2) + 8.0 * at(i, 1) - 8.0 * at(i, -1) + at(i, -2)) / 12.0;
                let second = (-at(i, 2) + 16.0 * at(i, 1) - 30.0 * at(i, 0) + 16.0 * at(i, -1)
                    - at(i, -2))
                    / 12.0;
                [values[i], first, second]
            })
            .collect();
        Self { knots }
    }

    /// Linear blend `(1−w) a + w b`.
    pub fn blend(a: &Self, b: &Self, w: f64) -> Self {
        let values = a
            .knots
            .iter()
            .zip(&b.knots)
            .map(|(x, y)| (1.0 - w) * x[0] + w * y[0])
            .collect();
        Self::from_samples(values)
    }

    /// Single-zone Wiebe pressure for one load point. The tables take milliseconds to integrate
    /// and every instance of the FMU (a sweep resets it for each speed point) asks for the same
    /// few, so the last `WIEBE_MEMO_SIZE` are kept for the process.
    pub fn wiebe(model: &WiebeModel, point: &CombustionPoint, geometry: &CylinderGeometry) -> Self {
        type Memo = Vec<(WiebeModel, CombustionPoint, CylinderGeometry, PressureCurve)>;
        static MEMO: std::sync::OnceLock<std::sync::Mutex<Memo>> = std::sync::OnceLock::new();
        let memo = MEMO.get_or_init(Default::default);
        let found = {
            // A panic while the lock was held leaves plain data behind: still usable.
            let memo = memo.lock().unwrap_or_else(|e| e.into_inner());
            memo.iter()
                .find(|(m, p, g, _)| m == model && p == point && g == geometry)
                .map(|(_, _, _, curve)| curve.clone())
        };
        if let Some(curve) = found {
            return curve;
        }
        let curve = Self::integrate_wiebe(model, point, geometry);
        let mut memo = memo.lock().unwrap_or_else(|e| e.into_inner());
        if memo.len() >= WIEBE_MEMO_SIZE {
            memo.remove(0);
        }
        memo.push((model.clone(), point.clone(), *geometry, curve.clone()));
        curve
    }

    /// Long on purpose: one integration of the closed cycle (Wiebe burn, Woschni wall heat, RK4 stages on the table's grid) whose running state would otherwise be passed between pieces.
    fn integrate_wiebe(
        model: &WiebeModel,
        point: &CombustionPoint,
        geometry: &CylinderGeometry,
    ) -> Self {
        let n = (720.0 / GRID_DEG).round() as usize;
        let step = GRID_DEG.to_radians();
        let ivc = model.ivc_deg.to_radians();
        let evo = model.evo_deg.to_radians();
        let blow = model.blowdown_deg.to_radians().max(step);
        let heat_rate = |theta: f64| -> f64 {
            point
                .stages
                .iter()
                .map(|s| {
                    let soc = s.start_deg.to_radians();
                    let dur = s.duration_deg.to_radians();
                    let z = (theta - soc) / dur;
                    if z <= 0.0 {
                        return 0.0;
                    }
                    let m1 = s.shape + 1.0;
                    point.heat * s.fraction * 6.908 * m1 / dur
                        * z.powf(s.shape)
                        * (-6.908 * z.powf(m1)).exp()
                })
                .sum()
        };
        let kappa = |theta: f64| {
            let w = ((theta - ivc) / (evo - ivc)).clamp(0.0, 1.0);
            model.kappa_compression + w * (model.kappa_expansion - model.kappa_compression)
        };
        let (v_ivc, _) = geometry.volume(ivc, model.compression_ratio);
        let combustion_start = point
            .stages
            .iter()
            .map(|s| s.start_deg.to_radians())
            .fold(f64::INFINITY, f64::min);
        let wall_loss = |theta: f64, p: f64, v: f64| -> f64 {
            let Some(wall) = &model.wall_heat else {
                return 0.0;
            };
            let omega = wall.reference_speed_rpm * std::f64::consts::PI / 30.0;
            let mean_piston_speed =
                4.0 * geometry.crank_radius * omega / (2.0 * std::f64::consts::PI);
            let temperature = wall.charge_temperature * p * v / (point.pressure_ivc * v_ivc);
            let motored = point.pressure_ivc * (v_ivc / v).powf(model.kappa_compression);
            let c2 = if theta >= combustion_start {
                3.24e-3
            } else {
                0.0
            };
            let velocity = 2.28 * mean_piston_speed
                + c2 * geometry.displacement() * wall.charge_temperature
                    / (point.pressure_ivc * v_ivc)
                    * (p - motored).max(0.0);
            let h = 3.26
                * geometry.bore.powf(-0.2)
                * (p * 1e-3).powf(0.8)
                * temperature.powf(-0.55)
                * velocity.powf(0.8);
            // Per radian of crank angle.
            h * geometry.wall_area(v) * (temperature - wall.wall_temperature) / omega
        };
        let dpdt = |theta: f64, p: f64| {
            let (v, dv) = geometry.volume(theta, model.compression_ratio);
            let k = kappa(theta);
            (k - 1.0) / v * (heat_rate(theta) - wall_loss(theta, p, v)) - k * p / v * dv
        };
        // RK4 on the table's grid from IVC to EVO: a 4× finer step changes the curve by less
        // than 3e-8 of its peak and costs 4× the start-up time.
        let h = step;
        let closed_steps = ((evo - ivc) / step).ceil() as usize;
        let mut closed = Vec::with_capacity(closed_steps + 1);
        let mut p = point.pressure_ivc;
        let mut theta = ivc;
        closed.push(p);
        for _ in 0..closed_steps {
            let k1 = dpdt(theta, p);
            let k2 = dpdt(theta + 0.5 * h, p + 0.5 * h * k1);
            let k3 = dpdt(theta + 0.5 * h, p + 0.5 * h * k2);
            let k4 = dpdt(theta + h, p + h * k3);
            p += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            theta += h;
            closed.push(p);
        }
        let p_evo = closed[closed.len() - 1];
        let charge = point.pressure_ivc;
        // The valve events are blended so that the curve stays C¹ (the integrator's error
        // estimate, and with it its accuracy, breaks down at a kink): before IVC the charge
        // pressure turns smoothly into the polytropic compression the closed cylinder starts
        // with; after EVO the polytropic expansion fades smoothly into the charge pressure over
        // the blow-down.
        let (v_evo, _) = geometry.volume(evo, model.compression_ratio);
        let compression = |th: f64| {
            let (v, _) = geometry.volume(th, model.compression_ratio);
            charge * (v_ivc / v).powf(model.kappa_compression)
        };
        let expansion = |th: f64| {
            let (v, _) = geometry.volume(th, model.compression_ratio);
            p_evo * (v_evo / v).powf(model.kappa_expansion)
        };
        // Ten degrees, or what the gas exchange leaves between blow-down and IVC.
        let lead_in = IVC_LEAD_IN_DEG
            .to_radians()
            .min(ivc + 4.0 * std::f64::consts::PI - evo - blow);
        // Phases are decided in degrees on the grid: in radians, rounding put the knot at EVO
        // outside both the closed phase and the blow-down, and the curve dropped to the charge
        // pressure at that one knot (a spike the integrator could not resolve: its error
        // stalled near 1e-4 whatever the tolerance).
        let (ivc_deg, evo_deg) = (model.ivc_deg, model.evo_deg);
        let knot_tolerance = 1e-9 * GRID_DEG;
        let values = (0..n)
            .map(|k| {
                let deg = -360.0 + k as f64 * GRID_DEG;
                let th = deg.to_radians();
                if deg >= ivc_deg - knot_tolerance && deg <= evo_deg + knot_tolerance {
                    let u = ((deg - ivc_deg) / GRID_DEG).max(0.0);
                    let i = (u.floor() as usize).min(closed.len() - 2);
                    let t = (u - i as f64).min(1.0);
                    return closed[i] + t * (closed[i + 1] - closed[i]);
                }
                // Angle since EVO within the 720° cycle (the cycle wraps between EVO and IVC).
                let since = if deg > evo_deg {
                    th - evo
                } else {
                    th + 4.0 * std::f64::consts::PI - evo
                };
                if since < blow {
                    let w = 1.0 - crate::model::blend::smooth_step(since / blow);
                    return charge + w * (expansion(evo + since) - charge);
                }
                // Angle before the next IVC (after EVO the next IVC is a cycle later).
                let before = if th < ivc {
                    ivc - th
                } else {
                    ivc + 4.0 * std::f64::consts::PI - th
                };
                if before < lead_in {
                    let w = 1.0 - crate::model::blend::smooth_step(before / lead_in);
                    return charge + w * (compression(th) - charge);
                }
                charge
            })
            .collect();
        Self::from_samples(values)
    }

    /// Resamples a user table (periodic linear interpolation, then C¹ Hermite on the grid).
    /// An empty or mismatched table is an error.
    pub fn from_table(table: &PressureTable) -> Result<Self, String> {
        if table.angle_deg.is_empty() || table.angle_deg.len() != table.pressure.len() {
            return Err(format!(
                "pressure table needs matching, non-empty angle and pressure lists, got {} and {}",
                table.angle_deg.len(),
                table.pressure.len()
            ));
        }
        let n = (720.0 / GRID_DEG).round() as usize;
        let pts: Vec<(f64, f64)> = table
            .angle_deg
            .iter()
            .zip(&table.pressure)
            .map(|(a, p)| ((a + 360.0).rem_euclid(720.0), *p))
            .collect();
        let mut sorted = pts;
        sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
        let values = (0..n)
            .map(|k| {
                let x = k as f64 * GRID_DEG;
                let m = sorted.len();
                let idx = sorted.iter().position(|(a, _)| *a > x).unwrap_or(m);
                let (a0, p0) = if idx == 0 {
                    (sorted[m - 1].0 - 720.0, sorted[m - 1].1)
                } else {
                    sorted[idx - 1]
                };
                let (a1, p1) = if idx == m {
                    (sorted[0].0 + 720.0, sorted[0].1)
                } else {
                    sorted[idx]
                };
                if a1 - a0 <= 0.0 {
                    p0
                } else {
                    p0 + (x - a0) / (a1 - a0) * (p1 - p0)
                }
            })
            .collect();
        Ok(Self::from_samples(values))
    }
}

/// Piston side force `F_N = F_gas tan β` with `sin β = λ sin ψ` (ψ = crank angle after TDC).
/// Positive: the piston presses against the cylinder wall in the +x direction of the block.
pub fn side_force(gas_force: f64, sin_psi: f64, lambda: f64) -> f64 {
    let sb = lambda * sin_psi;
    gas_force * sb / (1.0 - sb * sb).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry() -> CylinderGeometry {
        CylinderGeometry {
            bore: 0.085,
            crank_radius: 0.047,
            conrod: 0.047 / 0.3,
        }
    }

    /// With adiabatic walls the single-zone pressure equation is linear in the heat released, so
    /// scaling the heat by 1 + δ is the blend of the motored and the fired curve with weight
    /// 1 + δ (a check of the integration; with wall heat loss it is only the first-order term,
    /// and the powertrain integrates each cylinder's curve on its own).
    #[test]
    fn scaling_the_heat_scales_the_pressure_rise_over_the_motored_curve() {
        let model = WiebeModel {
            wall_heat: None,
            ..Default::default()
        };
        let point = &model.full_load;
        let fired = PressureCurve::wiebe(&model, point, &geometry());
        let motored = PressureCurve::wiebe(
            &model,
            &CombustionPoint {
                heat: 0.0,
                ..point.clone()
            },
            &geometry(),
        );
        for delta in [0.05, -0.1] {
            let direct = PressureCurve::wiebe(
                &model,
                &CombustionPoint {
                    heat: point.heat * (1.0 + delta),
                    ..point.clone()
                },
                &geometry(),
            );
            let blended = PressureCurve::blend(&motored, &fired, 1.0 + delta);
            for deg in [-100.0, -5.0, 0.0, 7.5, 20.0, 90.0, 200.0] {
                let th = f64::to_radians(deg);
                let (a, b) = (direct.pressure(th), blended.pressure(th));
                assert!((a - b).abs() < 1e-9 * a, "{deg}°: {a} vs {b}");
            }
        }
    }

    #[test]
    fn motored_cycle_follows_the_polytropic_law() {
        // No heat release, constant exponent, adiabatic walls: p V^κ = const between IVC and EVO
        // (independent truth).
        let mut model = WiebeModel {
            kappa_expansion: 1.36,
            wall_heat: None,
            ..Default::default()
        };
        model.idle.heat = 0.0;
        let curve = PressureCurve::wiebe(&model, &model.idle, &geometry());
        let g = geometry();
        let (v_ivc, _) = g.volume((-150f64).to_radians(), model.compression_ratio);
        for deg in [-120.0, -60.0, -10.0, 0.0, 30.0, 100.0] {
            let (v, _) = g.volume(f64::to_radians(deg), model.compression_ratio);
            let expect = 1.0e5 * (v_ivc / v).powf(1.36);
            let got = curve.pressure(f64::to_radians(deg));
            assert!(
                (got / expect - 1.0).abs() < 1e-4,
                "{deg}: {got} vs {expect}"
            );
        }
    }

    #[test]
    fn user_table_reproduces_a_tabulated_curve_and_rejects_bad_tables() {
        let model = WiebeModel::default();
        let wiebe = PressureCurve::wiebe(&model, &model.full_load, &geometry());
        let angle_deg: Vec<f64> = (0..1440).map(|k| -360.0 + 0.5 * k as f64).collect();
        let pressure = angle_deg
            .iter()
            .map(|a| wiebe.pressure(f64::to_radians(*a)))
            .collect();
        let table = PressureCurve::from_table(&PressureTable {
            angle_deg,
            pressure,
        })
        .expect("table");
        for deg in [-200.0, -30.0, 0.0, 7.3, 25.0, 180.0] {
            let (a, b) = (
                wiebe.pressure(f64::to_radians(deg)),
                table.pressure(f64::to_radians(deg)),
            );
            assert!((a - b).abs() < 2e-3 * wiebe.peak(), "{deg}: {a} vs {b}");
        }
        assert!(PressureCurve::from_table(&PressureTable {
            angle_deg: vec![],
            pressure: vec![]
        })
        .is_err());
    }

    /// Indicated efficiency `∮ p dV / Q` of the closed cycle (gross: no pumping loop, the
    /// model's gas exchange is at the charge pressure).
    fn efficiency(model: &WiebeModel, point: &CombustionPoint) -> f64 {
        let curve = PressureCurve::wiebe(model, point, &geometry());
        curve.indicated_work(&geometry(), model.compression_ratio) / point.heat
    }

    #[test]
    fn indicated_efficiency_is_a_diesels_once_the_walls_take_their_heat() {
        // A car DI diesel reaches a brake efficiency of about 40–43 % at its best point; with a
        // mechanical efficiency of 0.85–0.9 there and the pumping loop apart, its gross
        // indicated efficiency is about 45–50 %. The adiabatic single-zone cycle at compression
        // ratio 18.5 gives 58–62 %; Woschni's wall loss takes 8–10 points of it (this model:
        // 51 % at idle, 50 % at full load).
        let model = WiebeModel::default();
        let adiabatic = WiebeModel {
            wall_heat: None,
            ..Default::default()
        };
        for (name, point) in [("idle", &model.idle), ("full load", &model.full_load)] {
            let real = efficiency(&model, point);
            let ideal = efficiency(&adiabatic, point);
            assert!((0.45..0.52).contains(&real), "{name}: efficiency {real:.3}");
            assert!(
                ideal > real + 0.05,
                "{name}: adiabatic {ideal:.3} vs {real:.3}"
            );
        }
    }

    #[test]
    fn indicated_work_of_the_adiabatic_constant_volume_cycle_is_the_otto_efficiency() {
        // Independent truth: heat released at TDC in an instant (a very short Wiebe), one κ,
        // adiabatic walls: η = 1 − r^(1−κ) (the Otto cycle) up to the finite burn duration.
        let mut model = WiebeModel {
            kappa_expansion: 1.36,
            wall_heat: None,
            ivc_deg: -180.0,
            evo_deg: 180.0,
            blowdown_deg: 1.0,
            ..Default::default()
        };
        model.idle.stages = vec![WiebeStage {
            fraction: 1.0,
            start_deg: -0.5,
            duration_deg: 1.0,
            shape: 2.0,
        }];
        let eta = efficiency(&model, &model.idle);
        let otto = 1.0 - model.compression_ratio.powf(1.0 - 1.36);
        assert!((eta / otto - 1.0).abs() < 0.01, "{eta} vs Otto {otto}");
    }

    #[test]
    fn peak_pressures_are_in_the_design_ranges() {
        let model = WiebeModel::default();
        let idle = PressureCurve::wiebe(&model, &model.idle, &geometry()).peak();
        let full = PressureCurve::wiebe(&model, &model.full_load, &geometry()).peak();
        assert!((45e5..70e5).contains(&idle), "idle peak {idle}");
        assert!((120e5..165e5).contains(&full), "full-load peak {full}");
    }
}
