//! Snapshot at t1, run to t2; restore, run to t2 again: bitwise identical, also through the
//! serialisation.

use engine_mount_chassis::ode::test_problems::SpringChain;
use engine_mount_chassis::ode::{Bdf, BdfError, BdfOptions, BdfSnapshot};

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn restore_reproduces_the_run_bit_for_bit() {
    let mut p = SpringChain::standard(true).expect("standard chain");
    let y0 = vec![0.0; 40];
    let opts = BdfOptions {
        rtol: 1e-5,
        atol: engine_mount_chassis::ode::Tolerance::Scalar(1e-8),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, opts).unwrap();
    bdf.advance_to(&mut p, 0.1).unwrap();
    let snap = bdf.snapshot();
    let flat = snap.to_bytes();
    for k in 1..=20 {
        bdf.advance_to(&mut p, 0.1 + 0.01 * k as f64).unwrap();
    }
    let first = (bits(bdf.y()), bdf.stats().clone(), bdf.t());

    bdf.restore(&snap).unwrap();
    assert_eq!(bdf.t(), 0.1);
    for k in 1..=20 {
        bdf.advance_to(&mut p, 0.1 + 0.01 * k as f64).unwrap();
    }
    assert_eq!(first.0, bits(bdf.y()));
    assert_eq!(first.1, *bdf.stats());
    assert_eq!(first.2, bdf.t());

    // Through bytes into a fresh integrator.
    let mut other = Bdf::new(&mut p, 0.0, &y0, BdfOptions::default()).unwrap();
    other
        .restore(&BdfSnapshot::from_bytes(&flat).unwrap())
        .unwrap();
    for k in 1..=20 {
        other.advance_to(&mut p, 0.1 + 0.01 * k as f64).unwrap();
    }
    assert_eq!(first.0, bits(other.y()));
    assert_eq!(first.1, *other.stats());
}

#[test]
fn serialisation_rejects_foreign_and_damaged_buffers() {
    let mut p = SpringChain::standard(false).expect("standard chain");
    let y0 = vec![0.0; 40];
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, BdfOptions::default()).unwrap();
    bdf.advance_to(&mut p, 0.01).unwrap();
    let bytes = bdf.snapshot().to_bytes();
    assert_eq!(BdfSnapshot::from_bytes(&bytes).unwrap(), bdf.snapshot());
    assert!(matches!(
        BdfSnapshot::from_bytes(&bytes[..bytes.len() - 1]),
        Err(BdfError::BadSnapshot(_))
    ));
    let mut wrong_magic = bytes.clone();
    wrong_magic[0] ^= 1;
    assert!(matches!(
        BdfSnapshot::from_bytes(&wrong_magic),
        Err(BdfError::BadSnapshot(m)) if m.contains("magic")
    ));
    // The version follows the 8-byte magic (a one-byte varint for small versions).
    let mut wrong_version = bytes.clone();
    wrong_version[8] = 99;
    assert!(matches!(
        BdfSnapshot::from_bytes(&wrong_version),
        Err(BdfError::BadSnapshot(m)) if m.contains("version")
    ));
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(BdfSnapshot::from_bytes(&longer).is_err());
    assert!(matches!(
        BdfSnapshot::from_bytes(&[0u8; 7]),
        Err(BdfError::BadSnapshot(_))
    ));
    // A snapshot of another dimension is refused by restore.
    let mut small = engine_mount_chassis::ode::test_problems::VanDerPol { mu: 1.0 };
    let mut other = Bdf::new(&mut small, 0.0, &[2.0, 0.0], BdfOptions::default()).unwrap();
    assert!(matches!(
        other.restore(&bdf.snapshot()),
        Err(BdfError::BadSnapshot(_))
    ));
}
