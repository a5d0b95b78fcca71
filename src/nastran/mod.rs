//! Nastran bulk data input and output: a user's car body as a [`Mesh`].
//!
//! Reading: [`read_bulk_deck`] / [`read_bulk_deck_with`] / [`parse_str`] / [`parse_reader`] →
//! [`NastranBody`] (mesh + GRID id → node index).
//! Formats: small field, large field (`*`), free field (commas), continuations (`+`, `*`,
//! blank first field; a continuation marker must repeat field 10 of the line before, and the
//! last card may not end with a marker), `$` comments, optional executive and case control
//! before `BEGIN BULK` (only `SPC = n` is read from it; a deck without `BEGIN BULK` is all bulk
//! data), `ENDDATA`. Units are taken as given (use SI: m, kg, s, N).
//!
//! The reader streams: one physical line at a time (at most [`DeckLimits::max_line_bytes`],
//! a longer line is refused without reading its rest), each card handed to the model as soon as
//! it is complete, so memory follows the model, which [`DeckLimits`] bounds (cards, fields per
//! card), not the length of a line or a file. NUL and other control bytes, non-UTF-8 text and
//! non-ASCII bulk data are refused at their line.
//!
//! `INCLUDE 'file'` (quoted, the name may continue over lines; or one unquoted word) in the
//! bulk data reads `file` in place, relative to the including file's folder. Every file must lie
//! in [`DeckOptions::include_root`] (default: the top deck's folder), checked on the resolved
//! path (no `..` or symbolic link out of it); cycles and nesting deeper than
//! [`DeckLimits::max_include_depth`] are refused naming the chain; `INCLUDE` before `BEGIN BULK`
//! is refused (Nastran would read it as control statements, which this reader skips); a card
//! does not continue across files. Errors name the line and, in an included file, the file
//! (`line 12 of sub/grids.bdf`).
//!
//! Cards and how they map:
//! - GRID (CP → CORD2R/CORD2C/CORD2S, coordinates converted to basic; PS → supports), CORD2R,
//!   CORD2C (r, θ°, z), CORD2S (r, θ°, φ°) by three points in RID (RID chains, any kind).
//!   Users with fixed directions (CONM2/CONM1 CID, CBUSH CID) take rectangular systems only.
//! - GRID CD → [`crate::fe::mesh::Mesh::displacement_frames`]: the grid's six DOFs are its
//!   components along the CD system's axes at the grid (CORD2R axes; CORD2C r, θ, z and CORD2S
//!   r, θ, φ directions there, θ = φ = 0 on the axis). SPC/SPC1/PS components, CELAS/CDAMP
//!   components, RBE2 CM (of the dependent grid) and the RBE2 independent grid's six DOFs,
//!   RBE3 REFC (of the reference grid) and Ci (of each source grid), CBAR/CBEAM G vectors
//!   (OFFT) and the CBUSH X1..X3 (in GA's CD) are in CD, as in Nastran; elements and masses are
//!   formed in their own systems and transformed ([`crate::fe::nodal_frames`]). Motions
//!   recovered through [`crate::fe::dof::DofMap`] (mount and output points of a reduced body,
//!   mode shapes) are in basic. An unknown CD is refused naming the GRID and line.
//! - MAT1: two of E, G, NU given, the third by E = 2(1+ν)G (Nastran's rule); all three given:
//!   beams keep E and G, shells need G within 1 % of E/2(1+ν). RHO; GE/A/TREF ignored
//!   (structural damping is added modally by the caller). MAT2 (G11..G33, RHO) and MAT8 (E1, E2,
//!   NU12, G12, G1Z, G2Z, RHO) for shells (below); their thermal data, allowables and GE are
//!   read and not used. Material ids are shared by MAT1, MAT2 and MAT8.
//! - PSHELL (MID1, T, MID2, 12I/T³, MID3, TS/T, NSM; Z1/Z2 read and unused) with MAT1, MAT2
//!   or MAT8 for each MID, as Nastran defines them: membrane A = G₁·T, bending
//!   D = G₂·(12I/T³)·T³/12, transverse shear S = G₃·(TS/T)·T, where G is the MAT1 plane-stress
//!   matrix E/(1−ν²)\[1 ν 0; ν 1 0; 0 0 (1−ν)/2\] (G₃₃ = MAT1 G) and G·I for shear, the MAT2
//!   G11..G33 (as MID3: \[G11 G12; G12 G22\], G13/G23/G33 must be blank), or the MAT8 lamina
//!   (E1, E2, NU12, G12; shear diag(G1Z, G2Z), both blank = rigid, one blank refused). Mass
//!   per area = RHO(MID1)·T + NSM; rotary inertia (mass per area)·T_b²/12 with
//!   T_b = T·(12I/T³)^⅓. MID3 blank: no transverse shear flexibility (CQUAD4: a shear penalty
//!   [`crate::fe::shell::KIRCHHOFF_SHEAR_FACTOR`] times the bending stiffness over the element
//!   area, i.e. Kirchhoff). Refused: MID1 blank (no membrane), MID2 blank or −1 (membrane-only,
//!   plane strain), MID4 (membrane–bending coupling), the same id on a MAT1 and a MAT2/MAT8.
//!   MSC's PSHELL has no offset of its own (fields after MID4, e.g. OptiStruct's T0/ZOFFS, are
//!   refused); offsets come from the elements' ZOFFS.
//!   A PSHELL whose MID1, MID2, MID3 are one MAT1 (or equal ones) with TS/T = 5/6·(12I/T³)^⅓
//!   (5/6 for a homogeneous sheet; [`write_bulk_deck`] writes it so) and no offset is the plain
//!   isotropic sheet ([`crate::fe::mesh::Shell`] without a section, shear over 5/6 of the
//!   bending thickness, the same numbers as before); anything else carries a
//!   [`crate::fe::shell::ShellSection`].
//! - CQUAD4 → the QM6 + MITC4 shell ([`crate::fe::shell`], Mindlin: transverse shear from
//!   MID3); CTRIA3 → the CST + DKT shell ([`crate::fe::shell3`], Kirchhoff: MID3 does not
//!   enter). THETA: material axis 1 at THETA° from the side G1 → G2 (projected onto the element
//!   plane), about the element normal (G1 G2 G3 right-handed); MCID (integer in that field): the
//!   x axis of basic (0) or of a CORD2R projected onto the element plane (a curvilinear MCID is
//!   refused; for an all-MAT1 section the orientation is irrelevant and not looked up). ZOFFS:
//!   the reference plane lies ZOFFS along the element normal from the grid plane, carried
//!   rigidly (u_ref = u + θ × ZOFFS·n): K = Tᵀ K_ref T and the lumped mass likewise, which couples
//!   membrane and bending. Corner thicknesses (TFLAG, T1..T4) are refused.
//! - PBAR (A, I1, I2, J, NSM, K1, K2; I12 must be 0), PBEAM (constant section only; K1, K2),
//!   CBAR/CBEAM with X1..X3 or G0. I1 bends in Nastran's plane 1 (element x-y) → `iz`, I2 →
//!   `iy`; K1 (plane 1, shear along element y) → `shear_factor_y`, K2 → `shear_factor_z`: a
//!   Timoshenko beam with shear stiffness K·A·G ([`crate::fe::beam`]). PBAR K blank or 0.0 is
//!   rigid in shear (Euler-Bernoulli); PBEAM K blank is 1.0, 0.0 rigid in shear.
//! - CBAR/CBEAM offsets W1A..W3B and OFFT (blank = GGG) → [`crate::fe::mesh::BeamEnds`]
//!   `offsets` in basic: OFFT letter 1 is the system of X1..X3 (G: GA's CD, B: basic), letters
//!   2 and 3 those of the offsets at A and B (G: that grid's CD, O: the offset system, x from GA
//!   to GB, y in the plane of x and the orientation vector); GGG, BGG, GGO, BGO, GOG, BOG, GOO,
//!   BOO, anything else refused. The element runs between the offset ends, carried rigidly by
//!   the grids (K and lumped M: Tᵀ · T with the offset arms, [`crate::fe::beam`]).
//! - CBAR/CBEAM PA, PB (up to five distinct digits 1..6 per end, element axes) → `pins`:
//!   released by static condensation in element axes before the offsets; a release that leaves
//!   nothing to condense (a mechanism of the element, e.g. PA = PB = 1) carries nothing, as in
//!   NASTRAN; six digits at one end are refused. The lumped mass ignores the pin flags. CBEAM
//!   SA/SB (warping) and a real BIT in place of OFFT are refused.
//! - CTETRA (4 or 10 grids: mid-edge grids all given or all blank), CPENTA (6 grids), CHEXA
//!   (8 grids) with PSOLID (MID: an isotropic MAT1, E, G, NU consistent within 1 %; CORDM
//!   blank, 0, −1 or an existing system, irrelevant for an isotropic material; IN blank, 0 or
//!   BUBBLE; STRESS read and not used; ISOP blank; FCTN blank or SMECH; anything else refused
//!   naming the field) → [`crate::fe::mesh::Solid`] ([`crate::fe::solid`]: constant-strain and
//!   quadratic tetrahedra, linear wedge, hexahedron with incompatible modes in place of
//!   Nastran's bubble functions; consistent mass). 15-node CPENTA and 20-node CHEXA are refused.
//!   A zero-volume, inverted or folded element (Jacobian vanishing or changing sign at a node or
//!   integration point) is refused naming the card and line; a mirrored but valid numbering is
//!   accepted, as in Nastran. Solid grids have no rotational stiffness: assembly removes the
//!   rotations of grids that no element, spring or link holds (Nastran's AUTOSPC), so a CONM2
//!   inertia on such a grid is dropped as in Nastran.
//! - CONM2 (CID −1, 0 or a CORD2R; offset masses sit on an extra node rigidly linked to the
//!   grid, so the translation–rotation coupling is exact; products of inertia as in the QRG).
//! - CONM1 (lower triangle, CID blank/0 or a CORD2R): the matrix must be that of a rigid body
//!   (M11 = M22 = M33 = m, no translational coupling, rotation–translation block m·\[r\]×), which
//!   becomes a CONM2-like mass at offset r with inertia M(4..6) − m(|r|²I − r rᵀ); any other
//!   6 × 6 matrix is refused naming the card and line.
//! - CBUSH/PBUSH → [`crate::fe::mesh::Bush`]: K1..K6 and B1..B6 (viscous, into the damping
//!   matrix) along the element axes, which are CID (0 basic or a CORD2R), else x from GA to GB
//!   with y in the plane of X1..X3 / GO (like CBAR), else basic when GA and GB coincide or GB is
//!   blank (ground). The spring point lies at S (default 0.5) along GA–GB, carried rigidly by
//!   both ends. Refused: OCID other than −1, S1..S3, non-zero PBUSH GE; the RCV line (stress
//!   recovery) is read and not used. Bushes are not written back.
//! - CELAS1/PELAS, CELAS2, CDAMP1/PDAMP, CDAMP2: one component, to ground or between two grids
//!   along the same component. Merged per node / node pair.
//! - RBE2 → [`crate::fe::mesh::RigidLink`], RBE3 (no UM) → [`crate::fe::mesh::InterpolationLink`],
//!   both eliminated exactly in assembly.
//! - SPC1 (with THRU), SPC (zero displacement) of the set chosen by case control, or of the only
//!   set in the file.
//! - PARAM WTMASS (scales all mass), PARAM POST/GRDPNT/… (output only) and EIGRL/EIGR
//!   (extraction requests) are accepted; any other card is an error naming card and line and
//!   listing the supported cards (one table, [`card_table::CARD_TABLE`]: each row says how its
//!   cards are read (the parser in `cards/`, one file per family, and where the card is kept),
//!   what is refused and which cards the writer writes back; the card dispatch is the table and
//!   the user guide's card table is generated from it).
//! - GRIDs that no element, spring, damper, bush, mass or link references (coordinate
//!   definition grids, leftovers) get no DOFs: all six are constrained, as Nastran's AUTOSPC
//!   does, and [`NastranBody::unused_grids`] and a note in [`NastranBody::notes`] name them.
//!
//! Checks of the body ([`crate::fe::checks::check_mesh_named`] with [`DeckNames`] and
//! [`crate::fe::checks::CheckLimits::nastran_deck`]) name GRID ids and element cards with their
//! line, refuse only elements whose matrices would be wrong and count poor shapes as warnings.
//!
//! Writing: [`write_bulk_deck`] emits large-field cards for a mesh of the supported elements
//! (solids as CTETRA/CPENTA/CHEXA with one PSOLID per material; isotropic sheets only: a shell
//! with a [`crate::fe::shell::ShellSection`] is refused).
//!
//! Reduced bodies: [`read_dmig_file`] / [`write_dmig_file`] read and write Craig-Bampton
//! matrices as Nastran punches them (`DMIG`, see the `dmig` module).

pub mod card_table;
mod cards;
mod dmig;
mod lexer;
mod names;
mod reader;
mod to_mesh;
mod writer;

use std::collections::BTreeMap;
use std::path::Path;

pub use cards::DampingTableCard;
pub use dmig::{parse_dmig_str, read_dmig_file, write_dmig_file, DmigDof, DmigFile, DmigMatrix};
pub use lexer::{classify, parse_real, Deck, Field, Loc, RawCard, Value};
pub use names::DeckNames;
pub use reader::{lex, DeckLimits, DeckOptions};
pub use writer::write_bulk_deck;

use crate::fe::elements::Entity;
use crate::fe::error::FeError;
use crate::fe::mesh::Mesh;

/// Nastran ids of the mesh entities, by kind in mesh order (`of(Entity::Beam)[i]` is the
/// CBAR/CBEAM id of `mesh.beams[i]`, …). Merged scalar springs and dampers have none; a
/// CONM2/CONM1 with an offset appears among the masses and the rigid links.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ElementIds(BTreeMap<Entity, Vec<u32>>);

impl ElementIds {
    /// The ids of the entities of `kind`, in mesh order.
    pub fn of(&self, kind: Entity) -> &[u32] {
        self.0.get(&kind).map_or(&[], Vec::as_slice)
    }

    /// Records `id` as the id of the next entity of `kind`.
    pub fn push(&mut self, kind: Entity, id: u32) {
        self.0.entry(kind).or_default().push(id);
    }
}

/// A body read from bulk data.
#[derive(Debug, Clone, PartialEq)]
pub struct NastranBody {
    /// The mesh (no named nodes or regions: name points with [`NastranBody::name_points`]).
    pub mesh: Mesh,
    /// GRID id → node index. Nodes are numbered in ascending GRID id; nodes beyond the GRIDs
    /// are the centres of gravity of offset CONM2 masses.
    pub grid_index: BTreeMap<u32, usize>,
    /// Element ids per mesh entity.
    pub element_ids: ElementIds,
    /// The SPC set applied, if any.
    pub spc_set: Option<u32>,
    /// Element id → (where the card is, card name), for messages.
    pub element_cards: BTreeMap<u32, (Loc, &'static str)>,
    /// GRIDs no element, spring, damper, bush, mass or link references: all six DOFs
    /// constrained (no DOFs), as Nastran's AUTOSPC does.
    pub unused_grids: Vec<u32>,
    /// What the reader decided that the user should know (dropped grids), one log line each.
    pub notes: Vec<String>,
    /// The `TABDMP1` the case control's `SDAMPING` names, if any: the body's own modal damping.
    pub damping: Option<DampingTableCard>,
}

impl NastranBody {
    /// Node index of GRID `grid`.
    pub fn node(&self, grid: u32) -> Result<usize, FeError> {
        self.grid_index
            .get(&grid)
            .copied()
            .ok_or_else(|| FeError::InvalidInput(format!("GRID {grid} is not in the bulk data")))
    }

    /// Adds `name → GRID id` pairs (e.g. `"mount_front_left": 1001`) to `mesh.named_nodes`.
    pub fn name_points(&mut self, points: &BTreeMap<String, u32>) -> Result<(), FeError> {
        for (name, &grid) in points {
            let node = self
                .node(grid)
                .map_err(|e| FeError::InvalidInput(format!("point '{name}': {e}")))?;
            self.mesh.named_nodes.insert(name.clone(), node);
        }
        Ok(())
    }

    /// Adds `name → GRID ids` node sets to `mesh.regions` (mode descriptions need the regions
    /// of [`crate::chassis::region`], which a bulk data file does not carry).
    pub fn name_regions(&mut self, regions: &BTreeMap<String, Vec<u32>>) -> Result<(), FeError> {
        for (name, grids) in regions {
            let nodes = grids
                .iter()
                .map(|&g| self.node(g))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| FeError::InvalidInput(format!("region '{name}': {e}")))?;
            self.mesh.regions.insert(name.clone(), nodes);
        }
        Ok(())
    }
}

/// Parses bulk data text (see the module documentation for what is accepted; `INCLUDE` needs
/// a file: [`read_bulk_deck`]).
pub fn parse_str(text: &str) -> Result<NastranBody, FeError> {
    parse_reader(text.as_bytes(), &DeckLimits::default())
}

/// Parses bulk data from a reader, line by line (no `INCLUDE`: there is no folder to resolve
/// it against).
pub fn parse_reader(
    input: impl std::io::Read,
    limits: &DeckLimits,
) -> Result<NastranBody, FeError> {
    let mut cards = to_mesh::Collector::new();
    let info = reader::read_from(input, limits, &mut cards)?;
    to_mesh::build(cards, &info)
}

/// Reads a bulk data file and its `INCLUDE`s with the default [`DeckOptions`].
pub fn read_bulk_deck(path: &Path) -> Result<NastranBody, FeError> {
    let mut cards = to_mesh::Collector::new();
    let options = DeckOptions::default();
    let info =
        reader::read_file(path, &options, &mut cards, false).map_err(|e| prefixed(path, e))?;
    to_mesh::build(cards, &info).map_err(|e| prefixed(path, e))
}

fn prefixed(path: &Path, e: FeError) -> FeError {
    match e {
        FeError::InvalidInput(m) => FeError::InvalidInput(format!("{}: {m}", path.display())),
        other => other,
    }
}

/// Reads a bulk data file streaming: a regular file of UTF-8/ASCII text, its `INCLUDE 'file'`
/// statements (bulk data only) resolved relative to the including file and confined to
/// `options.include_root` (default: the deck's folder), within `options.limits`. Returns the
/// body and the deck's SHA-256 ([`deck_digest`]).
pub fn read_bulk_deck_with(
    path: &Path,
    options: &DeckOptions,
) -> Result<(NastranBody, String), FeError> {
    let mut cards = to_mesh::Collector::new();
    let info = reader::read_file(path, options, &mut cards, true).map_err(|e| prefixed(path, e))?;
    let body = to_mesh::build(cards, &info).map_err(|e| prefixed(path, e))?;
    Ok((body, info.sha256))
}

/// SHA-256 (hex) of a deck and its `INCLUDE`s, read streaming with the same rules as
/// [`read_bulk_deck_with`] (so a deck that does not lex is refused here already): of the file
/// itself when it includes nothing, else of the list of (file relative to the deck's folder,
/// SHA-256 of the file) in include order.
pub fn deck_digest(path: &Path, options: &DeckOptions) -> Result<String, FeError> {
    reader::read_file(path, options, &mut reader::Discard, true)
        .map(|info| info.sha256)
        .map_err(|e| prefixed(path, e))
}

/// Lexes bulk data from a reader without building a body and returns the largest line
/// buffer used (bytes): lets tests check that memory does not follow line or file length.
#[doc(hidden)]
pub fn lex_reader_peak_line_bytes(
    input: impl std::io::Read,
    limits: &DeckLimits,
) -> Result<usize, FeError> {
    reader::read_from(input, limits, &mut reader::Discard).map(|info| info.peak_line_bytes)
}
