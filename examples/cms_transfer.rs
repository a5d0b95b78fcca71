//! Transfer functions of the chassis alone (paper §5.3, Fig. 8): a harmonic unit vertical force
//! at the front-left engine-mount node → steering-wheel (vertical, lateral) and seat-rail
//! (vertical) acceleration, 5–150 Hz, from the reduced model with ADAMS damping.
//!
//! `cargo run --release --example cms_transfer [out.csv]` prints the response peaks and, with a
//! path, writes `f_hz` and the magnitude (m/s²/N) and phase (deg) of each response as CSV.
//! The reduction (fixed-interface modes to 450 Hz, three times the highest frequency shown) is
//! taken from the user cache when present.

use std::fmt::Write as _;

use engine_mount_chassis::cms::{
    reduce_cached, CacheSetting, ModeSelection, PointDof, ReductionSpec, Response,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let spec = ReductionSpec {
        selection: ModeSelection::CutoffHz(450.0),
        ..ReductionSpec::default()
    };
    let (reduced, outcome) = reduce_cached(&spec, &CacheSetting::Default)?;
    println!("{} modes; cache: {outcome:?}", reduced.n_modes());
    let input = PointDof {
        point: "mount_front_left",
        dof: 2,
    };
    let outputs = [
        (
            "steering_wheel_z",
            PointDof {
                point: "steering_wheel",
                dof: 2,
            },
        ),
        (
            "steering_wheel_y",
            PointDof {
                point: "steering_wheel",
                dof: 1,
            },
        ),
        (
            "seat_rail_z",
            PointDof {
                point: "seat_rail",
                dof: 2,
            },
        ),
    ];
    let freqs: Vec<f64> = (0..=1450).map(|i| 5.0 + 0.1 * f64::from(i)).collect();
    let mut responses = Vec::new();
    for (name, out) in outputs {
        let h = reduced.transfer_function(input, out, Response::Acceleration, &freqs)?;
        println!("{name}: peaks above 10 % of the largest (Hz, m/s²/N)");
        let top = h.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for i in 1..h.len() - 1 {
            let a = h[i].norm();
            if a > h[i - 1].norm() && a >= h[i + 1].norm() && a > 0.1 * top {
                println!("  {:7.2}  {a:.3e}", freqs[i]);
            }
        }
        responses.push(h);
    }
    if let Some(path) = std::env::args().nth(1) {
        let mut csv = String::from("f_hz");
        for (name, _) in outputs {
            write!(csv, ",{name}_abs,{name}_phase_deg")?;
        }
        csv.push('\n');
        for (i, f) in freqs.iter().enumerate() {
            write!(csv, "{f:.2}")?;
            for h in &responses {
                write!(csv, ",{:.6e},{:.2}", h[i].norm(), h[i].arg().to_degrees())?;
            }
            csv.push('\n');
        }
        std::fs::write(&path, csv)?;
        println!("wrote {path}");
    }
    Ok(())
}
