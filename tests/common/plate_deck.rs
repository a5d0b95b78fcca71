//! A small plate deck shared by the deck-diagnostics tests of the `fe` and `cms` binaries
//! (included by `#[path]`: each test binary links the crate on its own).

/// A 6 × 3 plate of 0.1 m CQUAD4s (GRID 1000 + 10 j + i, CQUAD4 1 + 6 j + i) with `extra`
/// cards; `lift` raises GRID 1036 (z, m).
pub fn plate(extra: &str, lift: f64) -> String {
    let mut deck = String::from("BEGIN BULK\nMAT1,1,2.1e11,,0.3,7850.\nPSHELL,1,1,0.002,1,,1\n");
    for j in 0..4 {
        for i in 0..7 {
            let z = if (i, j) == (6, 3) { lift } else { 0.0 };
            deck += &format!(
                "GRID,{},,{:?},{:?},{z:?}\n",
                1000 + 10 * j + i,
                0.1 * i as f64,
                0.1 * j as f64
            );
        }
    }
    for j in 0..3 {
        for i in 0..6 {
            let g = 1000 + 10 * j + i;
            deck += &format!(
                "CQUAD4,{},1,{g},{},{},{}\n",
                1 + 6 * j + i,
                g + 1,
                g + 11,
                g + 10
            );
        }
    }
    deck + extra + "ENDDATA\n"
}

/// CELAS2 springs of `stiffness` (N/m) to ground on the three translations of the plate's
/// corners (CELAS2 901–912): the plate is held.
pub fn corner_springs(stiffness: f64) -> String {
    let mut cards = String::new();
    for (k, g) in [1000, 1006, 1030, 1036].into_iter().enumerate() {
        for c in 1..=3 {
            cards += &format!("CELAS2,{},{stiffness:?},{g},{c}\n", 900 + 3 * k + c);
        }
    }
    cards
}
