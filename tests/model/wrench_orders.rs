//! Shared by the crank-drive order tests: the reaction wrench of a powertrain held on rigid
//! ground sampled over whole revolutions at constant speed, and its order amplitudes.

use engine_mount_chassis::model::orders::order_amplitude;
use engine_mount_chassis::model::Powertrain;

/// Samples per revolution.
pub const SPR: usize = 720;

/// Force and moment components `[Fx, Fy, Fz, Mx, My, Mz]` over `revs` revolutions at constant
/// speed `w`.
pub fn sample(p: &Powertrain, w: f64, revs: usize) -> Vec<[f64; 6]> {
    (0..revs * SPR)
        .map(|k| {
            let phi = 2.0 * std::f64::consts::PI * k as f64 / SPR as f64;
            let wr = p.crank_drive_wrench(phi, w, 0.0);
            [
                wr.force[0],
                wr.force[1],
                wr.force[2],
                wr.moment[0],
                wr.moment[1],
                wr.moment[2],
            ]
        })
        .collect()
}

/// Amplitude of component `comp` at `order`.
pub fn amp(x: &[[f64; 6]], comp: usize, order: f64) -> f64 {
    let v: Vec<f64> = x.iter().map(|s| s[comp]).collect();
    order_amplitude(&v, SPR, order).expect("whole periods")
}

/// Amplitude of a rotating or oscillating vector quantity of components `comps` (root of the sum
/// of squared component amplitudes).
pub fn vamp(x: &[[f64; 6]], comps: &[usize], order: f64) -> f64 {
    comps
        .iter()
        .map(|&c| amp(x, c, order).powi(2))
        .sum::<f64>()
        .sqrt()
}
