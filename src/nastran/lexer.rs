//! Bulk data lines → cards of fields: small field (8 columns), large field (16 columns, `*`),
//! free field (commas), continuation lines (`+`, `*` or blank first field), `$` comments,
//! optional executive/case control before `BEGIN BULK`, `ENDDATA`. Also Nastran's number forms.

use std::sync::Arc;

use crate::fe::error::FeError;

/// Where a card or field is: line, and the included file it is in (`None`: the deck itself).
/// Displays as `12` or `12 of sub/b.bdf`, so messages read "line 12 of sub/b.bdf".
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Loc {
    /// 1-based line number in its file.
    pub line: usize,
    /// The included file, relative to the top deck's folder.
    pub file: Option<Arc<str>>,
}

impl std::fmt::Display for Loc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.file {
            None => write!(f, "{}", self.line),
            Some(file) => write!(f, "{} of {file}", self.line),
        }
    }
}

/// One data field with where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Trimmed, upper-case text ("" for blank).
    pub text: String,
    /// 1-based line number in the file.
    pub line: usize,
    /// Nastran field number on that line (2..9 small/free field, 2..5 large field).
    pub position: usize,
}

/// A card: its name and data fields (Nastran field 2 of the first line onwards, continuation
/// markers removed).
#[derive(Debug, Clone, PartialEq)]
pub struct RawCard {
    /// Upper-case name without the large-field `*`.
    pub name: String,
    /// 1-based line of the card's first line.
    pub line: usize,
    /// The included file the card is in (`None`: the deck itself).
    pub file: Option<Arc<str>>,
    /// Data fields in order.
    pub fields: Vec<Field>,
}

impl RawCard {
    /// Where the card starts.
    pub fn loc(&self) -> Loc {
        self.loc_of_line(self.line)
    }

    /// Line `line` of the card's file.
    pub fn loc_of_line(&self, line: usize) -> Loc {
        Loc {
            line,
            file: self.file.clone(),
        }
    }
}

/// Receives cards one at a time as the deck is read, so only the model built from them stays in
/// memory.
pub(crate) trait CardSink {
    /// One complete card (continuations joined, trailing blank fields removed).
    fn card(&mut self, card: RawCard) -> Result<(), FeError>;
    /// Forgets every card so far: lines read before `BEGIN BULK` turned out to be control
    /// sections, not bulk data.
    fn reset(&mut self);
}

impl CardSink for Vec<RawCard> {
    fn card(&mut self, card: RawCard) -> Result<(), FeError> {
        self.push(card);
        Ok(())
    }

    fn reset(&mut self) {
        self.clear();
    }
}

/// The bulk data cards and what the case control selects.
#[derive(Debug, Clone, PartialEq)]
pub struct Deck {
    /// Cards in file order.
    pub cards: Vec<RawCard>,
    /// `SPC = n` of the case control, if any.
    pub spc_selection: Option<u32>,
}

/// A field's value by Nastran's typing rules: integers have no decimal point or exponent, reals
/// do (`1.`, `.5`, `1.5-3`, `7.85+3`, `2.1E11`, `1.D0`), character values start with a letter.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// Empty field.
    Blank,
    /// Integer.
    Int(i64),
    /// Real.
    Real(f64),
    /// Character string.
    Text(String),
}

/// Classifies a trimmed, upper-case field.
pub fn classify(text: &str) -> Result<Value, String> {
    if text.is_empty() {
        return Ok(Value::Blank);
    }
    let first = text.chars().next().unwrap_or(' ');
    if first.is_ascii_alphabetic() {
        return if text.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            Ok(Value::Text(text.to_string()))
        } else {
            Err(format!("'{text}' is not a valid character value"))
        };
    }
    let unsigned = text.strip_prefix(['+', '-']).unwrap_or(text);
    if !unsigned.is_empty() && unsigned.chars().all(|c| c.is_ascii_digit()) {
        return text
            .parse::<i64>()
            .map(Value::Int)
            .map_err(|_| format!("integer '{text}' is out of range"));
    }
    parse_real(text)
        .map(Value::Real)
        .ok_or_else(|| format!("'{text}' is not a number"))
}

/// Parses a Nastran real: optional sign, mantissa with a decimal point, optional exponent
/// written `E±n`, `D±n` or just `±n` (`1.5-3` = 1.5e-3).
pub fn parse_real(text: &str) -> Option<f64> {
    let (sign, body) = match text.as_bytes().first()? {
        b'-' => ("-", &text[1..]),
        b'+' => ("", &text[1..]),
        _ => ("", text),
    };
    let (mantissa, exponent) = match body.find(['E', 'D', 'e', 'd']) {
        Some(p) => (&body[..p], Some(&body[p + 1..])),
        None => match body.find(['+', '-']) {
            Some(p) if p > 0 => (&body[..p], Some(&body[p..])),
            _ => (body, None),
        },
    };
    let digits = mantissa.chars().filter(|c| c.is_ascii_digit()).count();
    let dots = mantissa.chars().filter(|&c| c == '.').count();
    if digits == 0 || dots > 1 || digits + dots != mantissa.len() {
        return None;
    }
    if exponent.is_none() && dots == 0 {
        return None; // an integer, not a real
    }
    let exponent = match exponent {
        None => String::new(),
        Some(e) => {
            let unsigned = e.strip_prefix(['+', '-']).unwrap_or(e);
            if unsigned.is_empty() || !unsigned.chars().all(|c| c.is_ascii_digit()) {
                return None;
            }
            format!("e{e}")
        }
    };
    let value: f64 = format!("{sign}{mantissa}{exponent}").parse().ok()?;
    value.is_finite().then_some(value)
}

pub(super) fn strip_comment(line: &str) -> &str {
    match line.find('$') {
        Some(p) => &line[..p],
        None => line,
    }
}

/// Tabs expand to the next multiple of 8 columns (the fixed-field grid).
fn expand_tabs(line: &str) -> String {
    let mut out = String::with_capacity(line.len() + 8);
    for c in line.chars() {
        if c == '\t' {
            let n = 8 - out.chars().count() % 8;
            out.extend(std::iter::repeat_n(' ', n));
        } else {
            out.push(c);
        }
    }
    out
}

fn column_slice(chars: &[char], from: usize, width: usize) -> String {
    chars
        .iter()
        .skip(from)
        .take(width)
        .collect::<String>()
        .trim()
        .to_ascii_uppercase()
}

pub(super) fn lex_error(loc: &Loc, message: impl std::fmt::Display) -> FeError {
    FeError::InvalidInput(format!("Nastran bulk data line {loc}: {message}"))
}

/// `text` for a message about a file that may not be a deck at all: at most 16 characters,
/// anything but printable ASCII shown as `?`, so a wrong path cannot make the error repeat the
/// content of an unrelated file.
pub(super) fn shown(text: &str) -> String {
    let mut out: String = text
        .chars()
        .take(16)
        .map(|c| if c.is_ascii_graphic() { c } else { '?' })
        .collect();
    if text.chars().count() > 16 {
        out.push_str("...");
    }
    out
}

/// One bulk data line cut into fields.
pub(super) struct SplitLine {
    /// Field 1: card name or continuation marker.
    pub first: String,
    /// Data fields `(text, Nastran field number)`.
    pub fields: Vec<(String, usize)>,
    /// Field 10: the continuation marker the next line must repeat ("" if blank).
    pub marker: String,
}

/// Field 1 must be a card name (letters and digits, `*` for large field) or a continuation
/// marker (blank, `+…`, `*…`). Checked before the data fields, so a file that is no deck gets
/// at most its first field repeated in the message.
fn check_first(first: &str, loc: &Loc) -> Result<(), FeError> {
    let name = first.trim_end_matches('*');
    let is_name = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric());
    if first.is_empty() || first.starts_with(['+', '*']) || is_name {
        Ok(())
    } else {
        Err(lex_error(
            loc,
            format!("'{}' is not a card name", shown(first)),
        ))
    }
}

/// Splits one bulk data line into its first field, data fields and continuation field.
pub(super) fn split_line(line: &str, loc: &Loc) -> Result<SplitLine, FeError> {
    if line.contains(',') {
        let parts: Vec<String> = line
            .split(',')
            .map(|p| p.trim().to_ascii_uppercase())
            .collect();
        let first = parts[0].clone();
        check_first(&first, loc)?;
        let per_line = if first.ends_with('*') { 4 } else { 8 };
        let data = &parts[1..];
        // The field after the data fields is the continuation field; beyond it the line is
        // malformed.
        if data.len() > per_line + 1 {
            return Err(lex_error(
                loc,
                format!(
                    "free-field line has {} data fields, at most {per_line} plus a continuation \
                     field are allowed",
                    data.len()
                ),
            ));
        }
        // A short line still stands for all its fields: the next line continues at field 2.
        let fields = (0..per_line)
            .map(|k| (data.get(k).cloned().unwrap_or_default(), k + 2))
            .collect();
        let marker = data.get(per_line).cloned().unwrap_or_default();
        return Ok(SplitLine {
            first,
            fields,
            marker,
        });
    }
    let chars: Vec<char> = expand_tabs(line).chars().collect();
    let first = column_slice(&chars, 0, 8);
    check_first(&first, loc)?;
    let (per_line, width) = if first.ends_with('*') {
        (4, 16)
    } else {
        (8, 8)
    };
    let mut fields = Vec::with_capacity(per_line);
    for k in 0..per_line {
        let text = column_slice(&chars, 8 + k * width, width);
        if text.contains(char::is_whitespace) {
            return Err(lex_error(
                loc,
                // The field's text is not repeated: the file may be no deck at all.
                format!(
                    "field {} contains a blank (fixed-format fields are {width} columns wide; \
                     check the alignment)",
                    k + 2
                ),
            ));
        }
        fields.push((text, k + 2));
    }
    let marker = column_slice(&chars, 72, 8);
    Ok(SplitLine {
        first,
        fields,
        marker,
    })
}

pub(super) fn is_begin_bulk(line: &str) -> bool {
    let compact: String = strip_comment(line)
        .chars()
        .filter(|c| !c.is_whitespace() && *c != ',')
        .take(9)
        .collect::<String>()
        .to_ascii_uppercase();
    compact.starts_with("BEGINBULK")
}

/// `SPC = n` in a case control line.
pub(super) fn case_control_spc(line: &str, loc: &Loc) -> Result<Option<u32>, FeError> {
    let head = line.trim_start().as_bytes();
    if head.len() < 3 || !head[..3].eq_ignore_ascii_case(b"SPC") {
        return Ok(None);
    }
    let upper = strip_comment(line).trim().to_ascii_uppercase();
    let Some(rest) = upper.strip_prefix("SPC") else {
        return Ok(None);
    };
    let Some(value) = rest.trim_start().strip_prefix('=') else {
        return Ok(None);
    };
    value.trim().parse::<u32>().map(Some).map_err(|_| {
        lex_error(
            loc,
            format!("case control '{}' is not SPC = <set id>", shown(&upper)),
        )
    })
}

/// `SDAMPING = n` of the case control (the command abbreviated to four letters at least, with
/// an optional `(STRUCTURE)`; `SDAMPING(FLUID)` concerns no structure and is passed over): the
/// `TABDMP1` of the structure's modal damping.
pub(super) fn case_control_sdamping(line: &str, loc: &Loc) -> Result<Option<u32>, FeError> {
    let upper = strip_comment(line).trim().to_ascii_uppercase();
    let word_end = upper
        .find(|c: char| !c.is_ascii_alphabetic())
        .unwrap_or(upper.len());
    let word = &upper[..word_end];
    if word.len() < 4 || !"SDAMPING".starts_with(word) {
        return Ok(None);
    }
    let bad = || {
        lex_error(
            loc,
            format!(
                "case control '{}' is not SDAMPING = <TABDMP1 id>",
                shown(&upper)
            ),
        )
    };
    let mut rest = upper[word_end..].trim_start();
    if let Some(qualified) = rest.strip_prefix('(') {
        let (qualifier, after) = qualified.split_once(')').ok_or_else(bad)?;
        match qualifier.trim() {
            "STRUCTURE" | "STRUC" => {}
            "FLUID" => return Ok(None),
            _ => return Err(bad()),
        }
        rest = after.trim_start();
    }
    let value = rest.strip_prefix('=').ok_or_else(bad)?;
    value.trim().parse::<u32>().map(Some).map_err(|_| bad())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nastran::lex;

    #[test]
    fn sdamping_in_its_spellings() {
        let loc = Loc {
            line: 3,
            file: None,
        };
        for (text, id) in [
            ("SDAMPING = 12", Some(12)),
            ("  sdamping=7 $ table", Some(7)),
            ("SDAMP = 3", Some(3)),
            ("SDAMPING(STRUCTURE) = 4", Some(4)),
            ("SDAMPING (FLUID) = 5", None),
            ("SPC = 1", None),
            ("SDA = 1", None),
            ("SUBCASE 1", None),
        ] {
            assert_eq!(case_control_sdamping(text, &loc).unwrap(), id, "{text}");
        }
        for text in [
            "SDAMPING = ALL",
            "SDAMPING(X) = 1",
            "SDAMPING 12",
            "SDAMPING = -1",
        ] {
            let e = case_control_sdamping(text, &loc).unwrap_err().to_string();
            assert!(
                e.contains("line 3") && e.contains("SDAMPING = <TABDMP1 id>"),
                "{e}"
            );
        }
    }

    #[test]
    fn nastran_reals_in_all_their_forms() {
        for (text, value) in [
            ("1.5-3", 1.5e-3),
            (".5", 0.5),
            ("7.85+3", 7850.0),
            ("-2.1E+11", -2.1e11),
            ("1.D0", 1.0),
            ("5.", 5.0),
            ("-.25E-2", -0.0025),
            ("+3.", 3.0),
            ("1E3", 1000.0),
        ] {
            assert_eq!(classify(text), Ok(Value::Real(value)), "{text}");
        }
        assert_eq!(classify("12"), Ok(Value::Int(12)));
        assert_eq!(classify("-7"), Ok(Value::Int(-7)));
        assert_eq!(classify(""), Ok(Value::Blank));
        assert_eq!(classify("THRU"), Ok(Value::Text("THRU".into())));
        for bad in ["1.2.3", "1.5-", "--1.", "1..", ".", "1.5E", "3,", "1.0X"] {
            assert!(classify(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn small_large_and_free_field_give_the_same_card() {
        let small = "GRID           1       0      1.     2.5   -3.-2\n";
        let large = "GRID*                  1               0              1.             2.5\n\
                     *             -3.-2\n";
        let free = "GRID,1,0,1.,2.5,-3.-2\n";
        let texts = |t: &str| -> Vec<String> {
            lex(t).unwrap().cards[0]
                .fields
                .iter()
                .map(|f| f.text.clone())
                .collect()
        };
        let expected: Vec<String> = ["1", "0", "1.", "2.5", "-3.-2"].map(String::from).to_vec();
        assert_eq!(texts(small), expected);
        assert_eq!(texts(large), expected);
        assert_eq!(texts(free), expected);
    }

    #[test]
    fn continuations_comments_and_control_sections() {
        let deck = concat!(
            "SOL 103\nCEND\nSUBCASE 1\n  SPC = 7\nBEGIN BULK\n",
            "$ a comment line\n",
            "CBAR,1,2,3,4,0.,0.,1.,,+C1 $ trailing comment\n",
            "+C1,,,1.0\n",
            "CQUAD4         5       6       1       2       3       4\n",
            "        0.\n",
            "ENDDATA\nGARBAGE after enddata\n",
        );
        let d = lex(deck).unwrap();
        assert_eq!(d.spc_selection, Some(7));
        assert_eq!(d.cards.len(), 2);
        let bar = &d.cards[0];
        assert_eq!((bar.name.as_str(), bar.line), ("CBAR", 7));
        assert_eq!(bar.fields.len(), 11);
        assert_eq!(bar.fields[10].text, "1.0");
        assert_eq!((bar.fields[10].line, bar.fields[10].position), (8, 4));
        let quad = &d.cards[1];
        assert_eq!(quad.fields.len(), 9);
        assert_eq!(quad.fields[8].text, "0.");
    }

    #[test]
    fn misaligned_fixed_field_and_orphan_continuation_name_the_line() {
        let err = lex("GRID    1 2\n").unwrap_err().to_string();
        assert!(err.contains("line 1") && err.contains("field 2"), "{err}");
        let err = lex("\n+C1,1\n").unwrap_err().to_string();
        assert!(
            err.contains("line 2") && err.contains("continuation"),
            "{err}"
        );
        let err = lex("INCLUDE 'x.bdf'\n").unwrap_err().to_string();
        assert!(err.contains("INCLUDE"), "{err}");
    }
}
