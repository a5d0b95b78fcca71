//! Bulk data text → cards: free field (comma separated) and small field (8 columns), with
//! continuation lines, comments, and the `BEGIN BULK` … `ENDDATA` section.

use crate::fe::FeError;

/// One bulk data card: its name, its data fields (field 2 on; continuation lines appended eight
/// at a time) and the line it starts on.
#[derive(Debug, Clone, PartialEq)]
pub struct Card {
    pub name: String,
    pub fields: Vec<String>,
    pub line: usize,
}

impl Card {
    fn error(&self, field: usize, message: &str) -> FeError {
        FeError::InvalidInput(format!(
            "{} card on line {}, field {}: {message}",
            self.name,
            self.line,
            field + 2
        ))
    }

    fn raw(&self, field: usize) -> &str {
        self.fields.get(field).map(|s| s.trim()).unwrap_or("")
    }

    /// Whether data field `field` (0 = the card's field 2) is blank.
    pub fn blank(&self, field: usize) -> bool {
        self.raw(field).is_empty()
    }

    /// An integer field; `default` when blank (`None`: required).
    pub fn int(&self, field: usize, default: Option<i64>) -> Result<i64, FeError> {
        let text = self.raw(field);
        if text.is_empty() {
            return default.ok_or_else(|| self.error(field, "a required integer is missing"));
        }
        text.parse()
            .map_err(|_| self.error(field, &format!("\"{text}\" is not an integer")))
    }

    /// A real field in Nastran's forms (`1.5`, `1.5E-3`, `1.5-3`, `.5`, `7.85+3`, `1.D6`);
    /// `default` when blank (`None`: required).
    pub fn real(&self, field: usize, default: Option<f64>) -> Result<f64, FeError> {
        let text = self.raw(field);
        if text.is_empty() {
            return default.ok_or_else(|| self.error(field, "a required real is missing"));
        }
        parse_real(text)
            .filter(|x| x.is_finite())
            .ok_or_else(|| self.error(field, &format!("\"{text}\" is not a real number")))
    }

    /// The text of a field (upper case), empty when blank.
    pub fn text(&self, field: usize) -> String {
        self.raw(field).to_ascii_uppercase()
    }

    /// An error about the card as a whole.
    pub fn invalid(&self, message: &str) -> FeError {
        FeError::InvalidInput(format!(
            "{} card on line {}: {message}",
            self.name, self.line
        ))
    }
}

/// Nastran's real number forms; an integer is not a real (Nastran insists on the point).
pub fn parse_real(text: &str) -> Option<f64> {
    let t = text.trim().to_ascii_uppercase().replace('D', "E");
    if !t.contains('.') {
        return None;
    }
    if let Ok(x) = t.parse::<f64>() {
        return Some(x);
    }
    // Exponent without the letter: a sign after the mantissa's first character.
    let bytes = t.as_bytes();
    let split = (1..bytes.len())
        .find(|&i| (bytes[i] == b'+' || bytes[i] == b'-') && bytes[i - 1] != b'E')?;
    let (mantissa, exponent) = t.split_at(split);
    format!("{mantissa}E{exponent}").parse().ok()
}

/// Fields of one line: the card-name field and up to eight data fields.
fn split_line(line: &str) -> (String, Vec<String>) {
    if line.contains(',') {
        let mut parts = line.split(',').map(|s| s.trim().to_owned());
        let first = parts.next().unwrap_or_default();
        let mut data: Vec<String> = parts.collect();
        data.truncate(8);
        (first, data)
    } else {
        let chars: Vec<char> = line.chars().collect();
        let field = |k: usize| -> String {
            let start = 8 * k;
            if start >= chars.len() {
                return String::new();
            }
            chars[start..(start + 8).min(chars.len())]
                .iter()
                .collect::<String>()
                .trim()
                .to_owned()
        };
        let first = field(0);
        let data = (1..9).map(field).collect();
        (first, data)
    }
}

/// The cards of a bulk data deck. Lines before `BEGIN BULK` (executive and case control) are
/// skipped when the deck has that line; reading stops at `ENDDATA`. Large-field (`*`) cards are
/// refused with their line.
pub fn cards(text: &str) -> Result<Vec<Card>, FeError> {
    let lines: Vec<&str> = text.lines().collect();
    let begin = lines
        .iter()
        .position(|l| {
            l.trim_start()
                .to_ascii_uppercase()
                .starts_with("BEGIN BULK")
        })
        .map_or(0, |i| i + 1);
    let mut cards: Vec<Card> = Vec::new();
    for (i, raw) in lines.iter().enumerate().skip(begin) {
        let number = i + 1;
        let line = raw.split('$').next().unwrap_or("").trim_end();
        if line.trim().is_empty() {
            continue;
        }
        if line
            .trim_start()
            .to_ascii_uppercase()
            .starts_with("ENDDATA")
        {
            break;
        }
        let (first, data) = split_line(line);
        let continuation = first.is_empty() || first.starts_with('+') || first.starts_with('*');
        if continuation {
            if first.starts_with('*') {
                return Err(FeError::InvalidInput(format!(
                    "line {number}: large-field continuation (*) is not supported; use free or small field"
                )));
            }
            let Some(card) = cards.last_mut() else {
                return Err(FeError::InvalidInput(format!(
                    "line {number}: a continuation line without a card before it"
                )));
            };
            // The previous line's data fields count as eight, blanks included.
            let filled = card.fields.len().div_ceil(8).max(1) * 8;
            card.fields.resize(filled, String::new());
            card.fields.extend(data);
            continue;
        }
        let name = first.to_ascii_uppercase();
        if name.ends_with('*') {
            return Err(FeError::InvalidInput(format!(
                "line {number}: large-field card {name} is not supported; use free or small field"
            )));
        }
        cards.push(Card {
            name,
            fields: data,
            line: number,
        });
    }
    Ok(cards)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nastran_reals() {
        for (text, value) in [
            ("1.5", 1.5),
            ("1.5E-3", 1.5e-3),
            ("1.5-3", 1.5e-3),
            (".5", 0.5),
            ("7.85+3", 7850.0),
            ("-2.+4", -2.0e4),
            ("1.D6", 1.0e6),
            ("2.1e11", 2.1e11),
        ] {
            assert_eq!(parse_real(text), Some(value), "{text}");
        }
        assert_eq!(parse_real("3"), None);
        assert_eq!(parse_real("abc"), None);
    }

    #[test]
    fn free_and_small_field_with_continuations_and_comments() {
        let deck = "SOL 103\nCEND\nBEGIN BULK\n$ a comment\nGRID,1,,0.,1.,2.\n\
                    GRID    2               1.      2.      3.\n\
                    CONM2   7       2               5.      \n\
                    +       1.      0.      2.      0.      0.      3.\n\
                    CONM2,8,1,,4.,,,,,+\n+,1.,,1.,,,1.\nENDDATA\nGRID,9,,0.,0.,0.\n";
        let cards = cards(deck).unwrap();
        assert_eq!(cards.len(), 4);
        assert_eq!(cards[0].name, "GRID");
        assert_eq!(cards[0].line, 5);
        assert_eq!(cards[0].real(2, None).unwrap(), 0.0);
        assert_eq!(cards[1].real(3, None).unwrap(), 2.0);
        assert_eq!(cards[2].int(1, None).unwrap(), 2);
        assert_eq!(cards[2].real(3, None).unwrap(), 5.0);
        assert_eq!(cards[2].real(8, None).unwrap(), 1.0);
        assert_eq!(cards[2].real(13, None).unwrap(), 3.0);
        assert_eq!(cards[3].real(8, None).unwrap(), 1.0);
        assert_eq!(cards[3].real(10, None).unwrap(), 1.0);
        assert_eq!(cards[3].real(13, None).unwrap(), 1.0);
    }

    #[test]
    fn malformed_fields_name_card_line_and_field() {
        let c = cards("GRID,1,,0.,x,0.\n").unwrap();
        let e = c[0].real(3, None).unwrap_err().to_string();
        assert!(
            e.contains("GRID card on line 1, field 5") && e.contains("\"x\""),
            "{e}"
        );
        assert!(cards("GRID*   1\n")
            .unwrap_err()
            .to_string()
            .contains("line 1"));
        assert!(cards("+,1.\n")
            .unwrap_err()
            .to_string()
            .contains("without a card"));
    }
}
