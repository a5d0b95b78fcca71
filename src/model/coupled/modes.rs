//! Linearisation at the static equilibrium and modal analysis (paper Table 1, left column on
//! rigid ground, middle column in the elastic body).
//!
//! The right-hand side with the engine at rest (crank standing, no gas, mounts linearised at the
//! operating point) is differentiated by central differences with respect to the vibration
//! coordinates (powertrain positions and velocities, modal coordinates and rates; not the crank
//! angle or the speed follower): the state matrix of [`super::linear`]. The equations are explicit, so the eigenvalues of `∂f/∂y` give
//! frequency `|λ|/2π` and damping `−Re λ/|λ|` (faer's dense eigen solver).
//!
//! Each mode is described by where its kinetic energy sits. A powertrain mode (more than half of
//! the kinetic energy in the powertrain) is a rigid-body mode when the mounts are strained more
//! than the ring carriers, else a ring-carrier mode; it is named by its dominant direction in the
//! paper's naming for the transverse engine: lateral = translation x, axial = translation along
//! the crank axis y, vertical = z, pitching = rotation about x, rolling = about the crank axis y,
//! yawing = about z. A body mode is named by the uncoupled body mode that carries most of its
//! energy and the body point that moves most.

use faer::Mat;
use nalgebra::{Matrix6, Vector3};
use num_complex::Complex64;

use super::decoupling::shift;
use super::CoupledModel;

/// Direction of a body motion, vehicle axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Translation x ("lateral" for the transverse engine).
    Lateral,
    /// Translation y, along the crank axis ("axial").
    Axial,
    /// Translation z.
    Vertical,
    /// Rotation about x ("pitching").
    Pitch,
    /// Rotation about the crank axis y ("rolling").
    Roll,
    /// Rotation about z ("yawing").
    Yaw,
}

impl Direction {
    /// In the order of the coordinates `[x, y, z, rx, ry, rz]`.
    pub const ALL: [Direction; 6] = [
        Self::Lateral,
        Self::Axial,
        Self::Vertical,
        Self::Pitch,
        Self::Roll,
        Self::Yaw,
    ];

    fn from_index(i: usize) -> Self {
        Self::ALL[i.min(5)]
    }

    /// The paper's wording.
    pub fn paper_name(&self) -> &'static str {
        match self {
            Self::Lateral => "lateral translation (x)",
            Self::Axial => "axial translation (y, crank axis)",
            Self::Vertical => "vertical translation (z)",
            Self::Pitch => "pitching (about x)",
            Self::Roll => "rolling (about crank axis y)",
            Self::Yaw => "yawing (about z)",
        }
    }
}

/// What a mode mostly is.
#[derive(Debug, Clone, PartialEq)]
pub enum ModeKind {
    /// The powertrain moves as a whole on its mounts.
    RigidBody(Direction),
    /// Monoblock against housing; `bushing` is the most strained ring carrier, `direction` its
    /// most strained local direction (translations and rotations as in [`Direction`]).
    RingCarrier {
        /// Name of the most strained ring carrier.
        bushing: String,
        /// Its most strained local direction.
        direction: Direction,
    },
    /// Most kinetic energy in the body: `mode` is the uncoupled body mode contributing most,
    /// `point` the body point with the largest translation.
    Body {
        /// Index of the uncoupled body mode contributing most.
        mode: usize,
        /// That body mode's frequency alone (Hz).
        uncoupled_hz: f64,
        /// The body point with the largest translation.
        point: String,
    },
}

/// One eigenmode of the linearised model.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// Natural frequency `|λ| / 2π` of the eigenvalue pair (Hz).
    pub frequency_hz: f64,
    /// Damping ratio `−Re λ / |λ|`.
    pub damping_ratio: f64,
    /// What the mode mostly is.
    pub kind: ModeKind,
    /// Readable description (e.g. "rolling (about crank axis y) of engine assembly").
    pub description: String,
    /// Share of the kinetic energy in the powertrain (the rest is in the body).
    pub powertrain_fraction: f64,
    /// Powertrain kinetic energy per direction `[x, y, z, rx, ry, rz]`, summed over the
    /// powertrain bodies, as fractions of the powertrain's kinetic energy.
    pub powertrain_directions: [f64; 6],
    /// The powertrain's kinetic energy per direction `[x, y, z, rx, ry, rz]` of each body's
    /// motion taken at the powertrain's common centre of mass, as fractions of the powertrain's
    /// kinetic energy (not clipped: a direction coupled to another through the inertia
    /// products can carry a small negative share): a row of the decoupling table.
    pub centre_of_mass_directions: [f64; 6],
    /// The same per powertrain body (name).
    pub kinetic_fractions: Vec<(String, [f64; 6])>,
    /// Strain energy fraction in the mounts (the rest is in the ring carriers).
    pub mount_strain_fraction: f64,
}

fn describe(kind: &ModeKind) -> String {
    match kind {
        ModeKind::RigidBody(d) => format!("{} of engine assembly", d.paper_name()),
        ModeKind::RingCarrier { bushing, direction } => match direction {
            Direction::Axial => "axial deformation of ring carriers".to_string(),
            Direction::Roll => "torsion deformation of ring carriers".to_string(),
            Direction::Vertical | Direction::Pitch => {
                format!("{bushing} ring carrier, ajar vertical")
            }
            Direction::Lateral | Direction::Yaw => format!("{bushing} ring carrier, ajar lateral"),
        },
        ModeKind::Body {
            mode,
            uncoupled_hz,
            point,
        } => format!("body mode {mode} ({uncoupled_hz:.2} Hz alone), largest motion at {point}"),
    }
}

/// Eigenpairs `(λ, x)` of the state matrix `a` with `Im λ > 0`: one per oscillatory mode (its
/// conjugate and the real, non-oscillating eigenvalues are dropped, as are rigid-body zeros).
pub(crate) fn oscillatory_eigenpairs(
    a: &Mat<f64>,
) -> Result<Vec<(Complex64, Vec<Complex64>)>, String> {
    let n = a.nrows();
    let eig = a
        .eigen()
        .map_err(|e| format!("eigen solver failed: {e:?}"))?;
    let s = eig.S();
    let u = eig.U();
    let mut pairs = Vec::new();
    for k in 0..n {
        let lambda = s[k];
        let mag = lambda.norm();
        if lambda.im <= 1e-6 * mag.max(1.0) || mag < 1e-3 {
            continue;
        }
        pairs.push((lambda, (0..n).map(|i| u[(i, k)]).collect()));
    }
    Ok(pairs)
}

/// Complex small displacement `u + θ × r` of a body point at lever `r` (vehicle frame).
fn point_motion(u: &[Complex64], theta: &[Complex64], r: &Vector3<f64>) -> Vector3<Complex64> {
    let u = Vector3::new(u[0], u[1], u[2]);
    let theta = Vector3::new(theta[0], theta[1], theta[2]);
    u + theta.cross(&r.map(Complex64::from))
}

impl CoupledModel {
    /// Eigenmodes at the equilibrium `y_eq` (from [`CoupledModel::static_equilibrium`]), sorted by
    /// frequency; overdamped and static eigenvalues are skipped.
    pub fn modes(&self, y_eq: &[f64]) -> Result<Vec<Mode>, String> {
        let jac = self.state_matrix(y_eq)?;
        let masses = self.body_masses(y_eq);
        let mut modes: Vec<Mode> = oscillatory_eigenpairs(&jac)?
            .into_iter()
            .map(|(lam, x)| self.describe_mode(y_eq, &x, lam, &masses))
            .collect();
        modes.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
        Ok(modes)
    }

    /// `x` is a mode shape over the vibration coordinates `[q, v, η, η̇]`.
    ///
    /// Long on purpose: one report of a mode shape, component by component.
    fn describe_mode(
        &self,
        y_eq: &[f64],
        x: &[Complex64],
        lam: Complex64,
        masses: &[(Matrix6<f64>, Vector3<f64>)],
    ) -> Mode {
        let nb = self.layout.bodies();
        let m = self.layout.modes();
        let (eta, eta_rate) = (12 * nb, 12 * nb + m);
        let mag = lam.norm();

        // Kinetic energy per powertrain body and direction from the velocity part of the shape.
        let mut kinetic = Vec::with_capacity(nb);
        let mut directions = [0.0; 6];
        let mut engine_kinetic = 0.0;
        // The same at the common centre of mass: each body's twist moved there (the decoupling
        // table's directions).
        let cg = Self::common_centre_of_mass(masses);
        let mut at_cg = [0.0; 6];
        for (b, (mb, at)) in masses.iter().enumerate() {
            let v = &x[6 * nb + 6 * b..6 * nb + 6 * b + 6];
            let t = shift(&(at - cg));
            let m_cg = (t.transpose() * mb * t).map(Complex64::from);
            let v_ref = nalgebra::Vector6::from_iterator(v.iter().copied());
            let w = t.map(Complex64::from).try_inverse().unwrap_or_default() * v_ref;
            let mw = m_cg * w;
            for i in 0..6 {
                at_cg[i] += (w[i].conj() * mw[i]).re;
            }
        }
        let at_cg_total: f64 = at_cg.iter().sum();
        for e in at_cg.iter_mut() {
            *e /= at_cg_total.max(f64::MIN_POSITIVE);
        }
        for (b, (mb, _)) in masses.iter().enumerate() {
            let v = &x[6 * nb + 6 * b..6 * nb + 6 * b + 6];
            let mut e = [0.0; 6];
            for i in 0..6 {
                let mv: Complex64 = (0..6).map(|j| v[j] * mb[(i, j)]).sum();
                e[i] = (v[i].conj() * mv).re.max(0.0);
                directions[i] += e[i];
                engine_kinetic += e[i];
            }
            kinetic.push((self.powertrain.bodies()[b].name.clone(), e));
        }
        let modal_kinetic: Vec<f64> = (0..m).map(|k| x[eta_rate + k].norm_sqr()).collect();
        let body_kinetic: f64 = modal_kinetic.iter().sum();
        let total = (engine_kinetic + body_kinetic).max(f64::MIN_POSITIVE);
        let engine_norm = engine_kinetic.max(f64::MIN_POSITIVE);
        for d in directions.iter_mut() {
            *d /= engine_norm;
        }
        for (_, e) in &mut kinetic {
            for v in e.iter_mut() {
                *v /= engine_norm;
            }
        }
        let powertrain_fraction = engine_kinetic / total;
        let eta_shape = &x[eta..eta + m];
        let (mount_strain, ring_strain, ring_best) = self.strain_energies(y_eq, x, eta_shape);

        let kind = if powertrain_fraction >= 0.5 {
            if ring_strain > mount_strain {
                ModeKind::RingCarrier {
                    bushing: ring_best.0,
                    direction: Direction::from_index(ring_best.1),
                }
            } else {
                let dominant = (0..6)
                    .max_by(|&a, &b| directions[a].total_cmp(&directions[b]))
                    .unwrap_or(0);
                ModeKind::RigidBody(Direction::from_index(dominant))
            }
        } else {
            let dominant = (0..m)
                .max_by(|&a, &b| modal_kinetic[a].total_cmp(&modal_kinetic[b]))
                .unwrap_or(0);
            let body = &self.body;
            let point = (0..body.points.len())
                .map(|p| {
                    let mut amp = Vector3::<Complex64>::zeros();
                    for (s, e) in body.points[p].shape.iter().zip(eta_shape) {
                        amp += Vector3::new(s[0], s[1], s[2]).map(Complex64::from) * *e;
                    }
                    (p, amp.iter().map(|a| a.norm_sqr()).sum::<f64>())
                })
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(p, _)| body.points[p].name.clone())
                .unwrap_or_default();
            ModeKind::Body {
                mode: dominant,
                uncoupled_hz: body.omega[dominant] / (2.0 * std::f64::consts::PI),
                point,
            }
        };
        Mode {
            frequency_hz: mag / (2.0 * std::f64::consts::PI),
            damping_ratio: -lam.re / mag,
            description: describe(&kind),
            kind,
            powertrain_fraction,
            powertrain_directions: directions,
            centre_of_mass_directions: at_cg,
            kinetic_fractions: kinetic,
            mount_strain_fraction: mount_strain
                / (mount_strain + ring_strain).max(f64::MIN_POSITIVE),
        }
    }

    /// Strain energies of a mode shape in the mounts and in the ring carriers, and the most
    /// strained ring carrier with its direction.
    fn strain_energies(
        &self,
        y_eq: &[f64],
        x: &[Complex64],
        eta_shape: &[Complex64],
    ) -> (f64, f64, (String, usize)) {
        let disp = |b: usize| (&x[6 * b..6 * b + 3], &x[6 * b + 3..6 * b + 6]);
        let hb = self.powertrain.housing_index();
        let kin_h = self.kinematics(y_eq, hb);
        let (uh, th_h) = disp(hb);
        let reference = self.powertrain.bodies()[hb].reference;
        let mut mount_strain = 0.0;
        for (i, m) in self.mounts.iter().enumerate() {
            let Some(m) = m else { continue };
            let mount = &m.mount;
            let r = kin_h.rotation * (mount.bracket - reference);
            let mut d = point_motion(uh, th_h, &r);
            if let super::MountTarget::BodyPoint(p) = m.target {
                for (s, e) in self.body.points[p].shape.iter().zip(eta_shape) {
                    d -= Vector3::new(s[0], s[1], s[2]).map(Complex64::from) * *e;
                }
            }
            let scale = self.inputs.mount_scales(i, self.fade_start).0;
            for axis in 0..3 {
                let local = mount
                    .axes
                    .row(axis)
                    .transpose()
                    .map(Complex64::from)
                    .dot(&d);
                let k = mount.curves[axis].stiffness(mount.operating_point[axis]);
                mount_strain += 0.5 * scale * k * local.norm_sqr();
            }
        }
        let mut ring_strain = 0.0;
        let mut best = (0.0, String::new(), 0);
        if self.layout.bodies() == 2 {
            let kin_m = self.kinematics(y_eq, 0);
            let (um, th_m) = disp(0);
            for rc in self.powertrain.ring_carriers() {
                let dm = point_motion(um, th_m, &(kin_m.rotation * rc.on_monoblock));
                let dh = point_motion(uh, th_h, &(kin_h.rotation * rc.on_housing));
                let rel = dm - dh;
                for i in 0..6 {
                    let r = if i < 3 {
                        rel[i]
                    } else {
                        th_m[i - 3] - th_h[i - 3]
                    };
                    let e = 0.5 * rc.stiffness[i] * r.norm_sqr();
                    ring_strain += e;
                    if e > best.0 {
                        best = (e, rc.name.clone(), i);
                    }
                }
            }
        }
        (mount_strain, ring_strain, (best.1, best.2))
    }
}

/// Formats modes as a table like the paper's Table 1 (with energy fractions).
pub fn mode_table(modes: &[Mode]) -> String {
    let mut s =
        String::from("  f [Hz]   zeta [%]  powertrain KE [%]  mount strain [%]  description\n");
    for m in modes {
        s += &format!(
            "{:8.2}  {:8.2}  {:17.0}  {:16.1}  {}\n",
            m.frequency_hz,
            100.0 * m.damping_ratio,
            100.0 * m.powertrain_fraction,
            100.0 * m.mount_strain_fraction,
            m.description
        );
    }
    s
}
