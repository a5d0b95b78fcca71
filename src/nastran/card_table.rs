//! The supported-card table: every bulk data card the reader accepts, what it becomes and which
//! of its fields are read, and the cards often met in production decks that it refuses, with what
//! to use instead. The dispatch of the deck reader takes exactly the cards of [`CARD_TABLE`], its
//! refusal of any other card lists them, and the user guide's table is generated from here
//! (`cargo run --example supported_cards`, run by `docs/generate.py`).

/// One row of the table of supported cards: what the reader makes of the cards it names and
/// which of their fields it reads. The dispatch takes exactly the cards of [`CARD_TABLE`] (a test
/// feeds each one), the refusal of any other card lists them, and the user guide's card table is
/// generated from it (`cargo run --example supported_cards`).
#[derive(Debug, Clone, Copy)]
pub struct CardSupport {
    /// The cards of the row.
    pub cards: &'static [&'static str],
    /// What they become.
    pub read_as: &'static str,
    /// The fields read; "read, not used" for those parsed and ignored.
    pub fields: &'static str,
    /// What of them is refused (an error naming card, file and line).
    pub refused: &'static str,
}

/// Every bulk data card the reader accepts, by row of the user guide's table.
pub const CARD_TABLE: [CardSupport; 25] = [
    CardSupport {
        cards: &["GRID"],
        read_as: "a node (six DOFs, in its CD system)",
        fields: "ID, CP, X1–X3, CD, PS (supports, whatever the SPC set)",
        refused: "SEID; an unknown CP or CD",
    },
    CardSupport {
        cards: &["CORD2R", "CORD2C", "CORD2S"],
        read_as: "coordinate systems by three points in RID (chains of any kind)",
        fields: "CID, RID, A1–A3, B1–B3, C1–C3",
        refused: "a cycle of RIDs; a curvilinear system where fixed directions are needed (CONM1/CONM2 CID, CBUSH CID, MCID)",
    },
    CardSupport {
        cards: &["MAT1"],
        read_as: "isotropic material",
        fields: "E, G, NU (two given: the third by E = 2(1+ν)G), RHO; GE, A, TREF read, not used",
        refused: "fewer than two of E, G, NU; for shells all three with G more than 1 % off E/2(1+ν)",
    },
    CardSupport {
        cards: &["MAT2", "MAT8"],
        read_as: "anisotropic and orthotropic shell materials",
        fields: "G11–G33, RHO / E1, E2, NU12, G12, G1Z, G2Z, RHO; thermal data, allowables, GE read, not used",
        refused: "use by a beam or a solid; an id shared with a MAT1; a MAT8 with one of G1Z, G2Z blank",
    },
    CardSupport {
        cards: &["PSHELL"],
        read_as: "a shell section: membrane MID1·T, bending MID2·12I/T³, transverse shear MID3·TS/T",
        fields: "MID1, T, MID2, 12I/T³, MID3 (blank: no shear flexibility), TS/T, NSM; Z1, Z2 read, not used",
        refused: "MID1 blank, MID2 blank or −1, MID4, fields after MID4",
    },
    CardSupport {
        cards: &["CQUAD4"],
        read_as: "QM6 membrane + MITC4 Mindlin plate, lumped mass",
        fields: "PID, G1–G4, THETA or MCID, ZOFFS",
        refused: "TFLAG, T1–T4 (corner thicknesses)",
    },
    CardSupport {
        cards: &["CTRIA3"],
        read_as: "CST membrane + DKT Kirchhoff plate, lumped mass",
        fields: "PID, G1–G3, THETA or MCID, ZOFFS",
        refused: "TFLAG, T1–T3",
    },
    CardSupport {
        cards: &["PBAR"],
        read_as: "a constant beam section, shear-flexible by K1, K2 (blank or 0: rigid in shear)",
        fields: "A, I1, I2, J, NSM, K1, K2; C1–F2 read, not used",
        refused: "I12 ≠ 0",
    },
    CardSupport {
        cards: &["PBEAM"],
        read_as: "a constant beam section, shear-flexible by K1, K2 (blank: 1.0; 0: rigid in shear)",
        fields: "A, I1, I2, J, NSM of end A (intermediate stations and end B must repeat them), K1, K2; stress recovery points, S1, S2 read, not used",
        refused: "I12 ≠ 0, tapered sections, NSI, CW, M1/M2, N1/N2",
    },
    CardSupport {
        cards: &["CBAR", "CBEAM"],
        read_as: "Timoshenko beam between offset ends, pin flags condensed, lumped mass",
        fields: "PID, GA, GB, X1–X3 or G0, OFFT, PA, PB, W1A–W3B",
        refused: "CBEAM SA, SB (warping); a real BIT in place of OFFT; OFFT other than GGG, BGG, GGO, BGO, GOG, BOG, GOO, BOO; six pin digits at one end",
    },
    CardSupport {
        cards: &["CTETRA"],
        read_as: "4-node or 10-node tetrahedron, consistent mass",
        fields: "PID, G1–G4 (G5–G10)",
        refused: "some mid-edge grids only",
    },
    CardSupport {
        cards: &["CPENTA"],
        read_as: "6-node wedge, consistent mass",
        fields: "PID, G1–G6",
        refused: "15 grids",
    },
    CardSupport {
        cards: &["CHEXA"],
        read_as: "8-node hexahedron with incompatible modes, consistent mass",
        fields: "PID, G1–G8",
        refused: "20 grids",
    },
    CardSupport {
        cards: &["PSOLID"],
        read_as: "solid property",
        fields: "MID (a MAT1), CORDM (blank, 0, −1 or a system), IN (blank, 0, BUBBLE), STRESS (not used), ISOP (blank), FCTN (blank, SMECH)",
        refused: "other IN, ISOP or FCTN values",
    },
    CardSupport {
        cards: &["CELAS1", "CELAS2", "PELAS"],
        read_as: "scalar spring to ground or between the same component of two grids",
        fields: "EID, PID (CELAS1) or K (CELAS2), G1, C1, G2, C2; PELAS PID, K; GE, S read, not used",
        refused: "different components at the two ends; scalar points",
    },
    CardSupport {
        cards: &["CDAMP1", "CDAMP2", "PDAMP"],
        read_as: "scalar viscous damper, likewise",
        fields: "EID, PID (CDAMP1) or B (CDAMP2), G1, C1, G2, C2; PDAMP PID, B",
        refused: "different components at the two ends; scalar points",
    },
    CardSupport {
        cards: &["CBUSH", "PBUSH"],
        read_as: "6-DOF spring (K1–K6) and viscous damper (B1–B6) in element axes",
        fields: "GA, GB (blank: ground), X1–X3 or GO, CID, S (default 0.5); PBUSH K, B; RCV read, not used",
        refused: "OCID other than −1, S1–S3, PBUSH GE ≠ 0",
    },
    CardSupport {
        cards: &["CONM2"],
        read_as: "point mass with inertia",
        fields: "G, CID (−1, 0 or a CORD2R), M, X1–X3, I11–I33",
        refused: "a curvilinear CID",
    },
    CardSupport {
        cards: &["CONM1"],
        read_as: "point mass from a 6 × 6 matrix",
        fields: "the lower triangle, CID (blank, 0 or a CORD2R)",
        refused: "a matrix that is not a rigid body's",
    },
    CardSupport {
        cards: &["RBE2"],
        read_as: "rigid element, eliminated exactly",
        fields: "GN, CM, GMi; ALPHA, TREF read, not used",
        refused: "a grid dependent in two links, or dependent and constrained",
    },
    CardSupport {
        cards: &["RBE3"],
        read_as: "interpolation element (weighted mean), eliminated exactly",
        fields: "REFGRID, REFC, WTi, Ci, Gi,j; ALPHA, TREF read, not used",
        refused: "UM",
    },
    CardSupport {
        cards: &["SPC", "SPC1"],
        read_as: "fixed DOFs of the selected set (case control SPC = n, or the only set)",
        fields: "SID, C, grids (SPC1 with THRU takes the grids that exist)",
        refused: "an enforced displacement ≠ 0; several sets and none selected",
    },
    CardSupport {
        cards: &["PARAM"],
        read_as: "WTMASS scales every mass; the output and bookkeeping parameters below are ignored",
        fields: "WTMASS",
        refused: "any other parameter (COUPMASS, K6ROT, …: they may change K or M)",
    },
    CardSupport {
        cards: &["TABDMP1"],
        read_as: "modal damping against frequency: the table the case control's SDAMPING names damps the reduced body",
        fields: "TID, TYPE (G, CRIT, Q), FLAT (blank or 1: end values held), pairs f, g up to ENDT (SKIP pairs left out)",
        refused: "FLAT = 0 (linear extrapolation); other TYPEs",
    },
    CardSupport {
        cards: &["EIGRL", "EIGR"],
        read_as: "ignored: the scene chooses the modes",
        fields: "",
        refused: "",
    },
];

/// Cards often met in production decks that the reader refuses (several to an entry, separated
/// by ", "), with what to use instead.
pub const REFUSED_CARDS: [(&str, &str); 12] = [
    (
        "PBARL, PBEAML",
        "the equivalent PBAR or PBEAM (A, I1, I2, J, K1, K2 of the section)",
    ),
    (
        "PCOMP, PCOMPG",
        "a PSHELL with MAT2 materials holding the laminate's membrane, bending and shear stiffness",
    ),
    (
        "CQUAD8, CTRIA6",
        "CQUAD4 and CTRIA3 on the corner grids (refine the mesh where needed)",
    ),
    ("CROD, CONROD", "a CBAR with a PBAR of the rod's A and J"),
    (
        "CWELD, CFAST",
        "a CBUSH with the connector's stiffness, or an RBE2",
    ),
    (
        "CGAP",
        "a CBUSH with the closed gap's stiffness (the body is linear)",
    ),
    (
        "RBAR",
        "an RBE2 (the same rigid link, one independent grid)",
    ),
    (
        "RBE1",
        "an RBE2 whose independent grid carries all six DOFs",
    ),
    (
        "MPC",
        "an RBE2 or RBE3 where the equation is a rigid link or a weighted mean",
    ),
    ("MAT9", "a MAT1 (solids take isotropic materials)"),
    (
        "CELAS3, CELAS4, SPOINT",
        "CELAS1 or CELAS2 between grid components",
    ),
    (
        "DMIG",
        "a body reduced in your own solver: `\"kind\": \"dmig\"` in the vehicle configuration",
    ),
];

/// `PARAM` names that only steer output or solution bookkeeping: accepted and ignored.
pub const IGNORED_PARAMS: [&str; 8] = [
    "POST", "GRDPNT", "AUTOSPC", "PRGPST", "MAXRATIO", "OGEOM", "NOCOMPS", "BAILOUT",
];

/// Every supported card, in the order of [`CARD_TABLE`].
pub fn supported_cards() -> impl Iterator<Item = &'static str> {
    CARD_TABLE.iter().flat_map(|row| row.cards.iter().copied())
}

/// `name` as the table spells it, if the reader supports it.
pub fn supported_card(name: &str) -> Option<&'static str> {
    supported_cards().find(|card| *card == name)
}

/// The supported cards as the refusal of another card lists them.
pub fn supported_list() -> String {
    supported_cards().collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_card_is_supported_twice_or_both_supported_and_refused() {
        let mut seen = std::collections::BTreeSet::new();
        for card in supported_cards() {
            assert!(seen.insert(card), "{card} is in two rows");
        }
        for (cards, instead) in REFUSED_CARDS {
            assert!(!instead.is_empty());
            for card in cards.split(", ") {
                assert!(
                    supported_card(card).is_none(),
                    "{card} is listed as refused"
                );
            }
        }
    }
}
