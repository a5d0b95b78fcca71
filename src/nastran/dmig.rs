//! Direct matrix input at points (`DMIG`), as Nastran punches a reduced component
//! (`PARAM,EXTOUT,DMIGPCH` or `EXTSEOUT(DMIGPCH)`): a header card per matrix and one column card
//! per column with entries.
//!
//! Header: `DMIG NAME 0 IFO TIN TOUT POLAR (blank) NCOL`; IFO 1 (square), 2 or 9 (rectangular),
//! 6 (symmetric: one triangle, or both if they agree); TIN 1 or 2 (real; complex matrices are
//! refused); POLAR blank or 0. Column: `DMIG NAME GJ CJ (blank) G1 C1 A1 B1 G2 C2 A2 B2 …`,
//! four fields per entry, `B` blank (real). A component is 1–6 for a grid point and 0 or blank
//! for a scalar point (`SPOINT`/`EPOINT`, as Nastran numbers the modal coordinates of the q-set).
//! Every format of the bulk data reader is accepted (small, large `DMIG*`, free field,
//! continuations, comments) and the file is read streaming like a deck ([`super::DeckOptions`]).
//!
//! Besides `DMIG`, a body file holds `GRID` cards for the positions of its points (CP and CD
//! blank or 0: positions and DOF components in the basic system). The cards an external
//! superelement punch carries besides (`SPOINT`, `EPOINT`, `ASET`, `ASET1`, `QSET`, `QSET1`,
//! `EXTRN`, `PLOTEL`, `DTI`, `CORD2R`, `CORD2C`, `CORD2S`, `PARAM`) are read and not used; any
//! other card is an error naming card and line.
//!
//! Writing: [`write_dmig_file`] emits free-field cards with 17 significant digits, so a matrix
//! read back is bit for bit the one written (a fixed-field punch keeps 10 digits).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::lexer::{classify, CardSink, Loc, RawCard, Value};
use super::reader::{read_file, read_text, DeckOptions};
use crate::fe::error::FeError;

/// A DOF of a DMIG matrix: grid or scalar point id and component (1–6 for a grid point, 0 for a
/// scalar point).
pub type DmigDof = (u32, u8);

/// One matrix of a DMIG file.
#[derive(Debug, Clone, PartialEq)]
pub struct DmigMatrix {
    /// Matrix name (upper case, e.g. `KAAX`).
    pub name: String,
    /// Form (IFO): 1 square, 2 or 9 rectangular, 6 symmetric.
    pub form: u8,
    /// Number of columns from the header (`NCOL`), if given.
    pub ncol: Option<usize>,
    /// Non-zero entries by (column DOF, row DOF). A symmetric matrix keeps each pair once, as
    /// given in the file.
    pub entries: BTreeMap<(DmigDof, DmigDof), f64>,
}

impl DmigMatrix {
    /// An empty matrix of this name and form.
    pub fn new(name: &str, form: u8) -> Self {
        Self {
            name: name.to_ascii_uppercase(),
            form,
            ncol: None,
            entries: BTreeMap::new(),
        }
    }

    /// Entry at (`row`, `col`); a symmetric matrix answers from either triangle.
    pub fn get(&self, row: DmigDof, col: DmigDof) -> f64 {
        match self.entries.get(&(col, row)) {
            Some(v) => *v,
            None if self.form == 6 => self.entries.get(&(row, col)).copied().unwrap_or(0.0),
            None => 0.0,
        }
    }

    /// Every DOF that appears as a row or a column, ascending.
    pub fn dofs(&self) -> std::collections::BTreeSet<DmigDof> {
        self.entries.keys().flat_map(|&(c, r)| [c, r]).collect()
    }

    /// Row DOFs, ascending.
    pub fn row_dofs(&self) -> std::collections::BTreeSet<DmigDof> {
        self.entries.keys().map(|&(_, r)| r).collect()
    }
}

/// A DMIG file: its matrices by name and the positions of its grid points.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DmigFile {
    /// Matrices by name.
    pub matrices: BTreeMap<String, DmigMatrix>,
    /// GRID id → position (basic system, m).
    pub grids: BTreeMap<u32, [f64; 3]>,
}

impl DmigFile {
    /// The matrix `name` (any case), or an error listing the matrices the file has.
    pub fn matrix(&self, name: &str) -> Result<&DmigMatrix, FeError> {
        self.matrices
            .get(&name.to_ascii_uppercase())
            .ok_or_else(|| {
                FeError::InvalidInput(format!(
                    "DMIG matrix {} is not in the file (it has: {})",
                    name.to_ascii_uppercase(),
                    if self.matrices.is_empty() {
                        "no DMIG matrix".to_owned()
                    } else {
                        self.matrices.keys().cloned().collect::<Vec<_>>().join(", ")
                    }
                ))
            })
    }
}

/// Cards read and not used (an external superelement punch carries them besides the matrices).
const IGNORED: [&str; 13] = [
    "SPOINT", "EPOINT", "ASET", "ASET1", "QSET", "QSET1", "EXTRN", "PLOTEL", "DTI", "CORD2R",
    "CORD2C", "CORD2S", "PARAM",
];

/// Relative difference up to which the two triangles of a symmetric matrix agree (a solver that
/// writes both prints the same number twice; 1e-9 leaves room for a last printed digit).
const SYMMETRY_TOLERANCE: f64 = 1e-9;

struct Collector {
    file: DmigFile,
    /// Where each entry was given, for the message about an inconsistent mirror entry.
    seen: BTreeMap<String, BTreeMap<(DmigDof, DmigDof), Loc>>,
    grid_loc: BTreeMap<u32, Loc>,
}

fn card_error(card: &RawCard, line: usize, message: impl std::fmt::Display) -> FeError {
    let loc = card.loc_of_line(line);
    let what = match card.fields.first() {
        Some(f) if card.name == "DMIG" => format!("DMIG {}", f.text),
        _ => card.name.clone(),
    };
    FeError::InvalidInput(format!("{what} card at line {loc}: {message}"))
}

impl Collector {
    fn field(card: &RawCard, i: usize) -> (&str, usize) {
        match card.fields.get(i) {
            Some(f) => (f.text.as_str(), f.line),
            None => ("", card.fields.last().map_or(card.line, |f| f.line)),
        }
    }

    fn int(card: &RawCard, i: usize, what: &str, blank: Option<i64>) -> Result<i64, FeError> {
        let (text, line) = Self::field(card, i);
        match classify(text) {
            Ok(Value::Int(v)) => Ok(v),
            Ok(Value::Blank) if blank.is_some() => Ok(blank.unwrap_or_default()),
            Ok(Value::Blank) => Err(card_error(card, line, format!("{what} is missing"))),
            _ => Err(card_error(
                card,
                line,
                format!("{what} = '{text}' must be an integer"),
            )),
        }
    }

    fn real(card: &RawCard, i: usize, what: &str, blank: Option<f64>) -> Result<f64, FeError> {
        let (text, line) = Self::field(card, i);
        match classify(text) {
            Ok(Value::Real(v)) if v.is_finite() => Ok(v),
            Ok(Value::Blank) if blank.is_some() => Ok(blank.unwrap_or_default()),
            Ok(Value::Blank) => Err(card_error(card, line, format!("{what} is missing"))),
            _ => Err(card_error(
                card,
                line,
                format!(
                    "{what} = '{text}' must be a finite real number (with a decimal point or \
                     an exponent)"
                ),
            )),
        }
    }

    fn grid(&mut self, card: &RawCard) -> Result<(), FeError> {
        let id = Self::int(card, 0, "the GRID id", None)?;
        let id = u32::try_from(id)
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| card_error(card, card.line, format!("GRID id {id} must be > 0")))?;
        for (i, what) in [(1, "CP"), (5, "CD")] {
            if Self::int(card, i, what, Some(0))? != 0 {
                return Err(card_error(
                    card,
                    card.line,
                    format!(
                        "GRID {id}: {what} must be blank or 0 (a DMIG body's positions and DOF \
                         components are in the basic system, the vehicle's axes)"
                    ),
                ));
            }
        }
        let mut x = [0.0; 3];
        for (k, v) in x.iter_mut().enumerate() {
            *v = Self::real(card, 2 + k, &format!("X{}", k + 1), Some(0.0))?;
        }
        if let Some(before) = self.grid_loc.insert(id, card.loc()) {
            return Err(card_error(
                card,
                card.line,
                format!("GRID {id} is also defined at line {before}"),
            ));
        }
        self.file.grids.insert(id, x);
        Ok(())
    }

    /// A DMIG card: the header (NAME, 0: form, types, NCOL) or one column (GJ, CJ and its
    /// (GI, CI, value) entries), added to its matrix.
    ///
    /// Long on purpose: the header and the column share the field layout and the checks (repeated
    /// entries, symmetry of a symmetric form against the entry already read); one card is one
    /// pass over its fields, each error naming the field it is about.
    fn dmig(&mut self, card: &RawCard) -> Result<(), FeError> {
        let (name, _) = Self::field(card, 0);
        if name.is_empty() {
            return Err(card_error(card, card.line, "the matrix name is missing"));
        }
        let name = name.to_owned();
        let gj = Self::int(card, 1, "GJ", None)?;
        if gj == 0 {
            return self.header(card, name);
        }
        let Some(matrix) = self.file.matrices.get(&name) else {
            return Err(card_error(
                card,
                card.line,
                format!("column card of matrix {name} before its header card (GJ = 0)"),
            ));
        };
        let symmetric = matrix.form == 6;
        let col = Self::dof(card, 1, "GJ", "CJ")?;
        let (blank, line) = Self::field(card, 3);
        if !blank.is_empty() {
            return Err(card_error(
                card,
                line,
                format!("field 5 must be blank on a column card, found '{blank}'"),
            ));
        }
        let n = card.fields.len().saturating_sub(4);
        if n == 0 {
            return Err(card_error(card, card.line, "column card without entries"));
        }
        let seen = self.seen.entry(name.clone()).or_default();
        for e in 0..n.div_ceil(4) {
            let at = 4 + 4 * e;
            let row = Self::dof(card, at, &format!("G{}", e + 1), &format!("C{}", e + 1))?;
            let value = Self::real(card, at + 2, &format!("A{}", e + 1), None)?;
            let (b, line) = Self::field(card, at + 3);
            if !b.is_empty() {
                return Err(card_error(
                    card,
                    line,
                    format!(
                        "B{} = '{b}' must be blank: the matrix is real (TIN 1 or 2)",
                        e + 1
                    ),
                ));
            }
            let line = card.fields[at].line;
            let here = card.loc_of_line(line);
            if let Some(first) = seen.get(&(col, row)) {
                return Err(card_error(
                    card,
                    line,
                    format!(
                        "entry (row {}/{}, column {}/{}) is also given at line {first}",
                        row.0, row.1, col.0, col.1
                    ),
                ));
            }
            if symmetric && row != col {
                if let Some(first) = seen.get(&(row, col)) {
                    let other = self.file.matrices[&name].entries[&(row, col)];
                    let scale = value.abs().max(other.abs());
                    if (value - other).abs() > SYMMETRY_TOLERANCE * scale {
                        return Err(card_error(
                            card,
                            line,
                            format!(
                                "matrix {name} is symmetric (IFO 6) but entry (row {}/{}, column \
                                 {}/{}) = {value:e} differs from its mirror {other:e} given at \
                                 line {first}",
                                row.0, row.1, col.0, col.1
                            ),
                        ));
                    }
                    seen.insert((col, row), here);
                    continue;
                }
            }
            seen.insert((col, row), here);
            if let Some(m) = self.file.matrices.get_mut(&name) {
                m.entries.insert((col, row), value);
            }
        }
        Ok(())
    }

    fn dof(card: &RawCard, at: usize, g: &str, c: &str) -> Result<DmigDof, FeError> {
        let id = Self::int(card, at, g, None)?;
        let comp = Self::int(card, at + 1, c, Some(0))?;
        let line = Self::field(card, at).1;
        let id = u32::try_from(id)
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| card_error(card, line, format!("{g} = {id} must be > 0")))?;
        if !(0..=6).contains(&comp) {
            return Err(card_error(
                card,
                line,
                format!("{c} = {comp} must be 1..6 (grid point) or 0/blank (scalar point)"),
            ));
        }
        Ok((id, comp as u8))
    }

    fn header(&mut self, card: &RawCard, name: String) -> Result<(), FeError> {
        let form = Self::int(card, 2, "IFO", None)?;
        if ![1, 2, 6, 9].contains(&form) {
            return Err(card_error(
                card,
                card.line,
                format!("IFO = {form}: the form must be 1, 2, 6 (symmetric) or 9"),
            ));
        }
        let tin = Self::int(card, 3, "TIN", None)?;
        if !(tin == 1 || tin == 2) {
            return Err(card_error(
                card,
                card.line,
                format!("TIN = {tin}: only real matrices (TIN 1 or 2) are read"),
            ));
        }
        Self::int(card, 4, "TOUT", Some(0))?;
        if Self::int(card, 5, "POLAR", Some(0))? != 0 {
            return Err(card_error(card, card.line, "POLAR must be blank or 0"));
        }
        let ncol = Self::int(card, 7, "NCOL", Some(0))?;
        if self.file.matrices.contains_key(&name) {
            return Err(card_error(
                card,
                card.line,
                format!("a second header card for matrix {name}"),
            ));
        }
        let mut m = DmigMatrix::new(&name, form as u8);
        m.ncol = usize::try_from(ncol).ok().filter(|&n| n > 0);
        self.file.matrices.insert(name, m);
        Ok(())
    }
}

impl CardSink for Collector {
    fn card(&mut self, card: RawCard) -> Result<(), FeError> {
        match card.name.as_str() {
            "DMIG" => self.dmig(&card),
            "GRID" => self.grid(&card),
            name if IGNORED.contains(&name) => Ok(()),
            name => Err(FeError::InvalidInput(format!(
                "{name} card at line {}: not part of a DMIG body file (DMIG matrices and GRID \
                 positions)",
                card.loc()
            ))),
        }
    }

    fn reset(&mut self) {
        self.file = DmigFile::default();
        self.seen.clear();
        self.grid_loc.clear();
    }
}

fn collector() -> Collector {
    Collector {
        file: DmigFile::default(),
        seen: BTreeMap::new(),
        grid_loc: BTreeMap::new(),
    }
}

/// Parses DMIG text (see the module documentation).
pub fn parse_dmig_str(text: &str) -> Result<DmigFile, FeError> {
    let mut c = collector();
    read_text(text, &Default::default(), &mut c)?;
    Ok(c.file)
}

/// Reads a DMIG file streaming (`INCLUDE`s confined as for a deck); errors name the file, card
/// and line. Returns the file and its SHA-256.
pub fn read_dmig_file(path: &Path, options: &DeckOptions) -> Result<(DmigFile, String), FeError> {
    let mut c = collector();
    let info = read_file(path, options, &mut c, true).map_err(|e| match e {
        FeError::InvalidInput(m) => FeError::InvalidInput(format!("{}: {m}", path.display())),
        other => other,
    })?;
    Ok((c.file, info.sha256))
}

/// A real in a form both Nastran and Rust read back exactly (17 significant digits).
fn real(v: f64) -> String {
    format!("{v:.16E}")
}

/// Writes GRID cards and DMIG matrices as free-field bulk data (17 significant digits; a
/// symmetric matrix as stored, normally its upper triangle).
pub fn write_dmig_file(grids: &BTreeMap<u32, [f64; 3]>, matrices: &[DmigMatrix]) -> String {
    let mut out = String::new();
    out.push_str(
        "$ Craig-Bampton body as direct matrix input (DMIG), written by engine_mount_chassis\n",
    );
    for (id, x) in grids {
        let _ = writeln!(
            out,
            "GRID,{id},,{},{},{}",
            real(x[0]),
            real(x[1]),
            real(x[2])
        );
    }
    for m in matrices {
        let ncol = match m.ncol {
            Some(n) => n.to_string(),
            None => String::new(),
        };
        let _ = writeln!(out, "DMIG,{},0,{},2,0,,,{ncol}", m.name, m.form);
        let mut column: Option<DmigDof> = None;
        let mut on_line = 0;
        for (&(col, row), &v) in &m.entries {
            if column != Some(col) {
                if column.is_some() {
                    out.push('\n');
                }
                let _ = write!(out, "DMIG,{},{},{},,", m.name, col.0, col.1);
                column = Some(col);
                on_line = 1;
            }
            // Eight data fields a line: the first line holds NAME GJ CJ (blank) and one entry,
            // the continuations two each.
            if on_line == 2 {
                out.push_str("\n,");
                on_line = 0;
            }
            let _ = write!(out, "{},{},{},,", row.0, row.1, real(v));
            on_line += 1;
        }
        if column.is_some() {
            out.push('\n');
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn punch_large_field_and_free_field_read_alike() {
        let punch = "\
DMIG    KAAX           0       6       2       0                       3
DMIG*   KAAX                          11               1
*                     11               1 2.000000000D+06
DMIG*   KAAX                          11               2
*                     11               2 1.500000000D+06
DMIG*   KAAX                         101
*                     11               1-1.000000000D+03
*                    101               0 4.000000000D+04
";
        let a = parse_dmig_str(punch).unwrap();
        let k = a.matrix("kaax").unwrap();
        assert_eq!(k.form, 6);
        assert_eq!(k.ncol, Some(3));
        assert_eq!(k.get((11, 1), (101, 0)), -1.0e3);
        assert_eq!(k.get((101, 0), (11, 1)), -1.0e3);
        assert_eq!(k.get((101, 0), (101, 0)), 4.0e4);
        let b =
            parse_dmig_str(&write_dmig_file(&BTreeMap::new(), std::slice::from_ref(k))).unwrap();
        assert_eq!(&b.matrices["KAAX"], k);
    }

    #[test]
    fn bad_cards_name_matrix_and_line() {
        let head = "DMIG,K,0,6,2,0\n";
        let e = parse_dmig_str(&format!(
            "{head}DMIG,K,1,1,,1,1,1.,,\n,2,1,3.,,\nDMIG,K,2,1,,1,1,3.5,\n"
        ))
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("DMIG K") && e.contains("line 4") && e.contains("line 3"),
            "{e}"
        );
        let e = parse_dmig_str(&format!("{head}DMIG,K,1,1,,1,1,1.E999,\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains("A1"), "{e}");
        let e = parse_dmig_str("DMIG,K,1,1,,1,1,1.,\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("before its header"), "{e}");
        let e = parse_dmig_str("DMIG,K,0,6,3,0\n").unwrap_err().to_string();
        assert!(e.contains("TIN = 3"), "{e}");
        let e = parse_dmig_str("CQUAD4,1,1,1,2,3,4\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("CQUAD4 card at line 1"), "{e}");
        let e = parse_dmig_str("GRID,1,5,0.,0.,0.\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("CP"), "{e}");
    }
}
