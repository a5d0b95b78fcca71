use engine_mount_chassis::cms::*;
fn main() {
    let spec = ReductionSpec {
        selection: ModeSelection::CutoffHz(225.0),
        ..ReductionSpec::default()
    };
    let (b, _) = reduce_cached(&spec, &CacheSetting::Default).unwrap();
    let w = b.point("steering_wheel").unwrap();
    for (k, (o, z)) in b.omega.iter().zip(&b.zeta).enumerate() {
        let s = &w.shape[k];
        println!(
            "{k:3} {:9.2} Hz zeta {:.3} wheel z {:+.3e}",
            o / 6.283185307179586,
            z,
            s[2]
        );
    }
}
