//! The supported-card table: every bulk data card the reader accepts, what it becomes and which
//! of its fields are read, and the cards often met in production decks that it refuses, with what
//! to use instead. The dispatch of the deck reader takes exactly the cards of [`CARD_TABLE`], its
//! refusal of any other card lists them, and the user guide's table is generated from here
//! (`cargo run --example supported_cards`, run by `docs/generate.py`).

//! The supported-card table: every bulk data card the reader accepts, how it is read (the
//! function that parses and checks its fields and where the card is kept), what it becomes,
//! which of its fields are read, what is refused and which cards the writer writes for what it
//! becomes; and the cards often met in production decks that it refuses, with what to use
//! instead. The deck reader's dispatch is this table (`read_card`), its refusal of any other
//! card lists the table's cards, and the user guide's table is generated from here (`cargo run
//! --example supported_cards`, run by `docs/generate.py`).

use super::cards::{
    self, insert_element, insert_unique, BeamProperty, Cards, Reader, ShellMaterialCard, Support,
    SystemKind,
};
use super::lexer::RawCard;
use crate::fe::error::FeError;

/// How one card is read: parsed and checked by [`super::cards`], kept in [`Cards`].
type Read = fn(&mut Cards, &Reader) -> Result<(), FeError>;

/// One card of a row.
#[derive(Clone, Copy)]
pub struct Card {
    /// Its name.
    pub name: &'static str,
    /// How it is read.
    read: Read,
}

impl std::fmt::Debug for Card {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

/// One row of the table of supported cards: how the reader reads the cards it names, what it
/// makes of them, which of their fields it reads, what it refuses and what the writer writes
/// back. The dispatch takes exactly the cards of [`CARD_TABLE`] (a test feeds each one), the
/// refusal of any other card lists them, and the user guide's card table is generated from it
/// (`cargo run --example supported_cards`).
#[derive(Debug, Clone, Copy)]
pub struct CardSupport {
    /// The cards of the row, each with how it is read.
    pub cards: &'static [Card],
    /// What they become.
    pub read_as: &'static str,
    /// The fields read; "read, not used" for those parsed and ignored.
    pub fields: &'static str,
    /// What of them is refused (an error naming card, file and line).
    pub refused: &'static str,
    /// The cards [`super::write_bulk_deck`] writes for what they become (cards of this row;
    /// empty: not written, or written as another row's card).
    pub written: &'static [&'static str],
}

/// Reads one card into `c` by its row of [`CARD_TABLE`]; any other card is refused naming it
/// and listing the supported ones.
pub(crate) fn read_card(c: &mut Cards, raw: &RawCard) -> Result<(), FeError> {
    let Some(card) = supported(&raw.name) else {
        return Err(cards::deck_error(
            raw.loc(),
            format!(
                "card {} is not supported (supported: {})",
                raw.name,
                supported_list()
            ),
        ));
    };
    (card.read)(c, &Reader::new(raw))
}

fn system(c: &mut Cards, r: &Reader, kind: SystemKind) -> Result<(), FeError> {
    let s = cards::cord2(r, kind)?;
    insert_unique(
        &mut c.systems,
        "coordinate system",
        s.id,
        &r.card().loc(),
        s,
    )
}

fn shell_material(c: &mut Cards, r: &Reader, m: ShellMaterialCard) -> Result<(), FeError> {
    let name = r.card().name.clone();
    insert_unique(&mut c.shell_materials, &name, m.id(), &r.card().loc(), m)
}

fn plate(c: &mut Cards, r: &Reader, corners: usize, name: &'static str) -> Result<(), FeError> {
    let p = cards::plate(r, corners)?;
    let line = r.card().loc();
    insert_element(
        &mut c.element_lines,
        &mut c.plates,
        name,
        p.id,
        &line,
        (p, name),
    )
}

fn beam_property(
    c: &mut Cards,
    r: &Reader,
    p: BeamProperty,
    name: &'static str,
) -> Result<(), FeError> {
    insert_unique(
        &mut c.beam_properties,
        "property",
        p.id,
        &r.card().loc(),
        (p, name),
    )
}

fn bar(c: &mut Cards, r: &Reader, name: &'static str) -> Result<(), FeError> {
    let b = cards::bar(r, name == "CBEAM")?;
    insert_element(
        &mut c.element_lines,
        &mut c.bars,
        name,
        b.id,
        &r.card().loc(),
        b,
    )
}

fn solid(c: &mut Cards, r: &Reader, name: &'static str) -> Result<(), FeError> {
    let e = cards::solid_element(r, name)?;
    insert_element(
        &mut c.element_lines,
        &mut c.solids,
        name,
        e.id,
        &r.card().loc(),
        e,
    )
}

/// CELAS1/CELAS2 (`spring`) or CDAMP1/CDAMP2: the value given directly by the card ending in 2.
fn scalar(c: &mut Cards, r: &Reader, name: &'static str, spring: bool) -> Result<(), FeError> {
    let s = cards::scalar(r, name.ends_with('2'), spring)?;
    let map = if spring {
        &mut c.springs
    } else {
        &mut c.dampers
    };
    insert_element(&mut c.element_lines, map, name, s.id, &r.card().loc(), s)
}

/// PELAS (K, four fields per entry) or PDAMP (B, two).
fn scalar_property(c: &mut Cards, r: &Reader, name: &'static str) -> Result<(), FeError> {
    let (per_entry, map) = if name == "PELAS" {
        (4, &mut c.spring_properties)
    } else {
        (2, &mut c.damper_properties)
    };
    let line = r.card().loc();
    for (pid, value) in cards::scalar_properties(r, per_entry)? {
        insert_unique(map, name, pid, &line, (value, line.clone()))?;
    }
    Ok(())
}

fn supports(c: &mut Cards, r: &Reader, list: Vec<Support>) -> Result<(), FeError> {
    let line = r.card().loc();
    c.supports
        .extend(list.into_iter().map(|s| (s, line.clone())));
    Ok(())
}

/// Every bulk data card the reader accepts, by row of the user guide's table.
pub const CARD_TABLE: [CardSupport; 25] = [
    CardSupport {
        cards: &[
            Card {
                name: "GRID",
                read: |c, r| {
            let g = cards::grid(r)?;
            insert_unique(&mut c.grids, "GRID", g.id, &r.card().loc(), g)
        },
            },
        ],
        read_as: "a node (six DOFs, in its CD system)",
        fields: "ID, CP, X1–X3, CD, PS (supports, whatever the SPC set)",
        refused: "SEID; an unknown CP or CD",
        written: &["GRID"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CORD2R",
                read: |c, r| system(c, r, SystemKind::Rectangular),
            },
            Card {
                name: "CORD2C",
                read: |c, r| system(c, r, SystemKind::Cylindrical),
            },
            Card {
                name: "CORD2S",
                read: |c, r| system(c, r, SystemKind::Spherical),
            },
        ],
        read_as: "coordinate systems by three points in RID (chains of any kind)",
        fields: "CID, RID, A1–A3, B1–B3, C1–C3",
        refused: "a cycle of RIDs; a curvilinear system where fixed directions are needed (CONM1/CONM2 CID, CBUSH CID, MCID)",
        written: &[],
    },
    CardSupport {
        cards: &[
            Card {
                name: "MAT1",
                read: |c, r| {
            let m = cards::mat1(r)?;
            insert_unique(&mut c.materials, "MAT1", m.id, &r.card().loc(), m)
        },
            },
        ],
        read_as: "isotropic material",
        fields: "E, G, NU (two given: the third by E = 2(1+ν)G), RHO; GE, A, TREF read, not used",
        refused: "fewer than two of E, G, NU; for shells all three with G more than 1 % off E/2(1+ν)",
        written: &["MAT1"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "MAT2",
                read: |c, r| shell_material(c, r, cards::mat2(r)?),
            },
            Card {
                name: "MAT8",
                read: |c, r| shell_material(c, r, cards::mat8(r)?),
            },
        ],
        read_as: "anisotropic and orthotropic shell materials",
        fields: "G11–G33, RHO / E1, E2, NU12, G12, G1Z, G2Z, RHO; thermal data, allowables, GE read, not used",
        refused: "use by a beam or a solid; an id shared with a MAT1; a MAT8 with one of G1Z, G2Z blank",
        written: &[],
    },
    CardSupport {
        cards: &[
            Card {
                name: "PSHELL",
                read: |c, r| {
            let p = cards::pshell(r)?;
            insert_unique(&mut c.shell_properties, "property", p.id, &r.card().loc(), p)
        },
            },
        ],
        read_as: "a shell section: membrane MID1·T, bending MID2·12I/T³, transverse shear MID3·TS/T",
        fields: "MID1, T, MID2, 12I/T³, MID3 (blank: no shear flexibility), TS/T, NSM; Z1, Z2 read, not used",
        refused: "MID1 blank, MID2 blank or −1, MID4, fields after MID4",
        written: &["PSHELL"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CQUAD4",
                read: |c, r| plate(c, r, 4, "CQUAD4"),
            },
        ],
        read_as: "QM6 membrane + MITC4 Mindlin plate, lumped mass",
        fields: "PID, G1–G4, THETA or MCID, ZOFFS",
        refused: "TFLAG, T1–T4 (corner thicknesses)",
        written: &["CQUAD4"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CTRIA3",
                read: |c, r| plate(c, r, 3, "CTRIA3"),
            },
        ],
        read_as: "CST membrane + DKT Kirchhoff plate, lumped mass",
        fields: "PID, G1–G3, THETA or MCID, ZOFFS",
        refused: "TFLAG, T1–T3",
        written: &["CTRIA3"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "PBAR",
                read: |c, r| beam_property(c, r, cards::pbar(r)?, "PBAR"),
            },
        ],
        read_as: "a constant beam section, shear-flexible by K1, K2 (blank or 0: rigid in shear)",
        fields: "A, I1, I2, J, NSM, K1, K2; C1–F2 read, not used",
        refused: "I12 ≠ 0",
        written: &["PBAR"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "PBEAM",
                read: |c, r| beam_property(c, r, cards::pbeam(r)?, "PBEAM"),
            },
        ],
        read_as: "a constant beam section, shear-flexible by K1, K2 (blank: 1.0; 0: rigid in shear)",
        fields: "A, I1, I2, J, NSM of end A (intermediate stations and end B must repeat them), K1, K2; stress recovery points, S1, S2 read, not used",
        refused: "I12 ≠ 0, tapered sections, NSI, CW, M1/M2, N1/N2",
        written: &[],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CBAR",
                read: |c, r| bar(c, r, "CBAR"),
            },
            Card {
                name: "CBEAM",
                read: |c, r| bar(c, r, "CBEAM"),
            },
        ],
        read_as: "Timoshenko beam between offset ends, pin flags condensed, lumped mass",
        fields: "PID, GA, GB, X1–X3 or G0, OFFT, PA, PB, W1A–W3B",
        refused: "CBEAM SA, SB (warping); a real BIT in place of OFFT; OFFT other than GGG, BGG, GGO, BGO, GOG, BOG, GOO, BOO; six pin digits at one end",
        written: &["CBAR"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CTETRA",
                read: |c, r| solid(c, r, "CTETRA"),
            },
        ],
        read_as: "4-node or 10-node tetrahedron, consistent mass",
        fields: "PID, G1–G4 (G5–G10)",
        refused: "some mid-edge grids only",
        written: &["CTETRA"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CPENTA",
                read: |c, r| solid(c, r, "CPENTA"),
            },
        ],
        read_as: "6-node wedge, consistent mass",
        fields: "PID, G1–G6",
        refused: "15 grids",
        written: &["CPENTA"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CHEXA",
                read: |c, r| solid(c, r, "CHEXA"),
            },
        ],
        read_as: "8-node hexahedron with incompatible modes, consistent mass",
        fields: "PID, G1–G8",
        refused: "20 grids",
        written: &["CHEXA"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "PSOLID",
                read: |c, r| {
            let p = cards::psolid(r)?;
            insert_unique(&mut c.solid_properties, "PSOLID", p.id, &r.card().loc(), p)
        },
            },
        ],
        read_as: "solid property",
        fields: "MID (a MAT1), CORDM (blank, 0, −1 or a system), IN (blank, 0, BUBBLE), STRESS (not used), ISOP (blank), FCTN (blank, SMECH)",
        refused: "other IN, ISOP or FCTN values",
        written: &["PSOLID"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CELAS1",
                read: |c, r| scalar(c, r, "CELAS1", true),
            },
            Card {
                name: "CELAS2",
                read: |c, r| scalar(c, r, "CELAS2", true),
            },
            Card {
                name: "PELAS",
                read: |c, r| scalar_property(c, r, "PELAS"),
            },
        ],
        read_as: "scalar spring to ground or between the same component of two grids",
        fields: "EID, PID (CELAS1) or K (CELAS2), G1, C1, G2, C2; PELAS PID, K; GE, S read, not used",
        refused: "different components at the two ends; scalar points",
        written: &["CELAS2"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CDAMP1",
                read: |c, r| scalar(c, r, "CDAMP1", false),
            },
            Card {
                name: "CDAMP2",
                read: |c, r| scalar(c, r, "CDAMP2", false),
            },
            Card {
                name: "PDAMP",
                read: |c, r| scalar_property(c, r, "PDAMP"),
            },
        ],
        read_as: "scalar viscous damper, likewise",
        fields: "EID, PID (CDAMP1) or B (CDAMP2), G1, C1, G2, C2; PDAMP PID, B",
        refused: "different components at the two ends; scalar points",
        written: &["CDAMP2"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CBUSH",
                read: |c, r| {
            let b = cards::cbush(r)?;
            insert_element(&mut c.element_lines, &mut c.bushes, "CBUSH", b.id, &r.card().loc(), b)
        },
            },
            Card {
                name: "PBUSH",
                read: |c, r| {
            let p = cards::pbush(r)?;
            insert_unique(&mut c.bush_properties, "PBUSH", p.id, &r.card().loc(), p)
        },
            },
        ],
        read_as: "6-DOF spring (K1–K6) and viscous damper (B1–B6) in element axes",
        fields: "GA, GB (blank: ground), X1–X3 or GO, CID, S (default 0.5); PBUSH K, B; RCV read, not used",
        refused: "OCID other than −1, S1–S3, PBUSH GE ≠ 0",
        written: &[],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CONM2",
                read: |c, r| {
            let m = cards::conm2(r)?;
            insert_element(&mut c.element_lines, &mut c.masses, "CONM2", m.id, &r.card().loc(), m)
        },
            },
        ],
        read_as: "point mass with inertia",
        fields: "G, CID (−1, 0 or a CORD2R), M, X1–X3, I11–I33",
        refused: "a curvilinear CID",
        written: &["CONM2"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "CONM1",
                read: |c, r| {
            let m = cards::conm1(r)?;
            insert_element(&mut c.element_lines, &mut c.general_masses, "CONM1", m.id, &r.card().loc(), m)
        },
            },
        ],
        read_as: "point mass from a 6 × 6 matrix",
        fields: "the lower triangle, CID (blank, 0 or a CORD2R)",
        refused: "a matrix that is not a rigid body's",
        written: &[],
    },
    CardSupport {
        cards: &[
            Card {
                name: "RBE2",
                read: |c, r| {
            let e = cards::rbe2(r)?;
            insert_element(&mut c.element_lines, &mut c.rigid, "RBE2", e.id, &r.card().loc(), e)
        },
            },
        ],
        read_as: "rigid element, eliminated exactly",
        fields: "GN, CM, GMi; ALPHA, TREF read, not used",
        refused: "a grid dependent in two links, or dependent and constrained",
        written: &["RBE2"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "RBE3",
                read: |c, r| {
            let e = cards::rbe3(r)?;
            insert_element(&mut c.element_lines, &mut c.interpolation, "RBE3", e.id, &r.card().loc(), e)
        },
            },
        ],
        read_as: "interpolation element (weighted mean), eliminated exactly",
        fields: "REFGRID, REFC, WTi, Ci, Gi,j; ALPHA, TREF read, not used",
        refused: "UM",
        written: &["RBE3"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "SPC",
                read: |c, r| supports(c, r, cards::spc(r)?),
            },
            Card {
                name: "SPC1",
                read: |c, r| supports(c, r, cards::spc1(r)?),
            },
        ],
        read_as: "fixed DOFs of the selected set (case control SPC = n, or the only set)",
        fields: "SID, C, grids (SPC1 with THRU takes the grids that exist)",
        refused: "an enforced displacement ≠ 0; several sets and none selected",
        written: &["SPC1"],
    },
    CardSupport {
        cards: &[
            Card {
                name: "PARAM",
                read: |c, r| c.param(r, &IGNORED_PARAMS),
            },
        ],
        read_as: "WTMASS scales every mass; the output and bookkeeping parameters below are ignored",
        fields: "WTMASS",
        refused: "any other parameter (COUPMASS, K6ROT, …: they may change K or M)",
        written: &[],
    },
    CardSupport {
        cards: &[
            Card {
                name: "TABDMP1",
                read: |c, r| {
            let t = cards::tabdmp1(r)?;
            insert_unique(&mut c.damping_tables, "TABDMP1", t.id, &r.card().loc(), t)
        },
            },
        ],
        read_as: "modal damping against frequency: the table the case control's SDAMPING names damps the reduced body",
        fields: "TID, TYPE (G, CRIT, Q), FLAT (blank or 1: end values held), pairs f, g up to ENDT (SKIP pairs left out)",
        refused: "FLAT = 0 (linear extrapolation); other TYPEs",
        written: &[],
    },
    CardSupport {
        cards: &[
            Card {
                name: "EIGRL",
                read: |_, _| Ok(()),
            },
            Card {
                name: "EIGR",
                read: |_, _| Ok(()),
            },
        ],
        read_as: "ignored: the scene chooses the modes",
        fields: "",
        refused: "",
        written: &[],
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
    CARD_TABLE
        .iter()
        .flat_map(|row| row.cards.iter().map(|card| card.name))
}

/// The card `name` of the table, if the reader supports it.
fn supported(name: &str) -> Option<&'static Card> {
    CARD_TABLE
        .iter()
        .flat_map(|row| row.cards.iter())
        .find(|card| card.name == name)
}

/// `name` as the table spells it, if the reader supports it.
pub fn supported_card(name: &str) -> Option<&'static str> {
    supported(name).map(|card| card.name)
}

/// The supported cards as the refusal of another card lists them.
pub fn supported_list() -> String {
    supported_cards().collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nastran::{parse_str, write_bulk_deck};

    /// A deck with every card the writer writes (and a bush and a displacement system, which it
    /// does not).
    const EVERY_KIND: &str = "BEGIN BULK
CORD2C,8,,0.,0.,0.,0.,0.,1.
,1.,0.,0.
MAT1,1,2.1e11,,0.3,7850.
PSHELL,1,1,0.002,1,,1
PBAR,3,1,1.e-4,2.e-9,3.e-9,4.e-9,0.2
PSOLID,4,1
PBUSH,5,K,1.e5,2.e5,3.e5,10.,20.,30.
PELAS,6,5.e4
GRID,1,,0.,0.,0.
GRID,2,,0.1,0.,0.
GRID,3,,0.1,0.1,0.
GRID,4,,0.,0.1,0.,8
GRID,5,,0.2,0.,0.
GRID,6,,0.2,0.1,0.01
GRID,7,,0.,0.,0.1
GRID,8,,0.1,0.,0.1
GRID,9,,0.1,0.1,0.1
GRID,10,,0.,0.1,0.1
GRID,11,,0.3,0.05,0.
GRID,12,,0.5,0.05,0.
GRID,13,,0.05,0.05,0.3
GRID,14,,0.,0.,0.2
GRID,15,,0.1,0.,0.2
GRID,16,,0.,0.1,0.2
CQUAD4,1,1,1,2,3,4
CTRIA3,2,1,2,5,6
CHEXA,4,4,1,2,3,4,7,8
,9,10
CTETRA,5,4,7,8,10,13
CPENTA,16,4,7,8,10,14,15,16
CBAR,6,3,5,11,0.,0.,1.
CBAR,7,3,11,12,0.,0.,1.
CONM2,8,12,,3.
CELAS1,11,6,12,1,11,1
CDAMP2,12,50.,12,2
CBUSH,13,5,12,,,,,0
RBE2,14,13,123456,9
RBE3,15,,5,123,1.,123,2,3
SPC1,1,123456,1
ENDDATA
";

    /// The `written` column is the writer: every card written for a mesh with every kind is in
    /// the column of its own row, and every card of the column is written.
    #[test]
    fn the_written_column_is_what_the_writer_writes() {
        let mut mesh = parse_str(EVERY_KIND).unwrap().mesh;
        mesh.bushes.clear();
        mesh.displacement_frames.clear();
        let text = write_bulk_deck(&mesh).unwrap();
        let written: std::collections::BTreeSet<&str> = text
            .lines()
            .filter_map(|l| l.split_whitespace().next()?.strip_suffix('*'))
            .filter(|name| !name.is_empty())
            .collect();
        for row in CARD_TABLE {
            for name in row.written {
                assert!(
                    row.cards.iter().any(|c| c.name == *name),
                    "{name} is written for a row that does not read it"
                );
                assert!(
                    written.contains(name),
                    "{name} is listed as written but is not"
                );
            }
        }
        for name in written {
            assert!(
                CARD_TABLE.iter().any(|row| row.written.contains(&name)),
                "the writer writes {name}, which no row lists as written"
            );
        }
    }

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
