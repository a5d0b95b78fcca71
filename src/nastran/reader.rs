//! The streaming deck reader: physical lines through a `BufRead` with a cap per line, cards
//! handed to a [`CardSink`] one at a time, `INCLUDE` files opened as they come. Memory holds one
//! line, the card being continued and the open files, so it grows with the model the sink
//! builds, not with the length of a line or of a file.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use sha2::{Digest, Sha256};

use super::lexer::{
    case_control_sdamping, case_control_spc, is_begin_bulk, lex_error, shown, split_line,
    strip_comment, CardSink, Deck, Field, Loc, RawCard,
};
use crate::fe::error::FeError;

/// What a deck may hold. The defaults suit production decks of a few GB of bulk data; raise
/// them for larger models (the card count is what bounds the memory of the model).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DeckLimits {
    /// Longest physical line (bytes, without the line end). Fixed-field lines have 80 columns;
    /// free-field lines are longer but not by this much. A longer line is refused after reading
    /// at most this many bytes of it. Default 64 KiB.
    pub max_line_bytes: usize,
    /// Most cards in the bulk data (all files together). Default 20 000 000.
    pub max_cards: usize,
    /// Most data fields of one card (continuations included). Default 1 000 000.
    pub max_card_fields: usize,
    /// Deepest nesting of `INCLUDE` files (the deck itself is depth 0). Default 16.
    pub max_include_depth: usize,
}

impl Default for DeckLimits {
    fn default() -> Self {
        Self {
            max_line_bytes: 64 << 10,
            max_cards: 20_000_000,
            max_card_fields: 1_000_000,
            max_include_depth: 16,
        }
    }
}

/// How a deck file is read.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct DeckOptions {
    /// The folder the deck and its `INCLUDE` files must lie in; `None`: the deck's own folder.
    pub include_root: Option<PathBuf>,
    /// Size limits.
    pub limits: DeckLimits,
}

/// What reading a deck found besides its cards.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DeckInfo {
    /// `SPC = n` of the case control, if any.
    pub spc_selection: Option<u32>,
    /// `SDAMPING = n` of the case control and where it is, if any.
    pub sdamping: Option<(u32, Loc)>,
    /// SHA-256 (hex) of the deck: of the file itself when it includes nothing, else of the
    /// list of (file, SHA-256 of the file) in the order the files were opened ("" unless
    /// hashing was asked for).
    pub sha256: String,
    /// Largest line buffer used (bytes): evidence that memory does not follow line length.
    pub peak_line_bytes: usize,
}

/// Hashes every byte read through it (if asked to: hashing costs as much as lexing).
struct Hashing<R> {
    inner: R,
    hasher: Option<Sha256>,
}

impl<R: Read> Read for Hashing<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if let Some(h) = &mut self.hasher {
            h.update(&buf[..n]);
        }
        Ok(n)
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// One open file (or in-memory text).
struct Source<'a> {
    reader: BufReader<Hashing<Box<dyn Read + 'a>>>,
    /// How messages name the file (`None`: the deck itself, whose path the caller prefixes).
    name: Option<Arc<str>>,
    /// How an INCLUDE chain names the file.
    label: String,
    /// Canonical path (`None`: text in memory).
    path: Option<PathBuf>,
    line: usize,
    /// Index into the digest list.
    slot: usize,
}

impl<'a> Source<'a> {
    fn new(read: Box<dyn Read + 'a>, name: Option<Arc<str>>, label: String, hash: bool) -> Self {
        Self {
            reader: BufReader::with_capacity(
                64 << 10,
                Hashing {
                    inner: read,
                    hasher: hash.then(Sha256::new),
                },
            ),
            name,
            label,
            path: None,
            line: 0,
            slot: 0,
        }
    }
}

enum LineRead {
    Eof,
    Line,
    TooLong,
    /// A NUL byte at this 1-based column.
    Nul(usize),
}

/// Reads one physical line into `buf` (without its `\n`), never more than `cap + 1` bytes of
/// it: a longer line is reported without reading its rest.
fn read_line_capped(
    r: &mut impl BufRead,
    buf: &mut Vec<u8>,
    cap: usize,
) -> std::io::Result<LineRead> {
    buf.clear();
    loop {
        let avail = r.fill_buf()?;
        if avail.is_empty() {
            return Ok(if buf.is_empty() {
                LineRead::Eof
            } else {
                LineRead::Line
            });
        }
        let room = cap + 1 - buf.len();
        let window = &avail[..avail.len().min(room)];
        let newline = window.iter().position(|&b| b == b'\n');
        let take = newline.unwrap_or(window.len());
        if let Some(p) = window[..take].iter().position(|&b| b == 0) {
            return Ok(LineRead::Nul(buf.len() + p + 1));
        }
        buf.extend_from_slice(&window[..take]);
        match newline {
            Some(p) => {
                r.consume(p + 1);
                return Ok(LineRead::Line);
            }
            None => {
                r.consume(take);
                if buf.len() > cap {
                    return Ok(LineRead::TooLong);
                }
            }
        }
    }
}

/// Where the reader is in the deck's sections.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    /// No `BEGIN BULK` seen yet: the lines may be executive and case control (if a `BEGIN
    /// BULK` follows) or bulk data (if none does). Both readings run until that is known.
    Unknown {
        bulk_ended: bool,
    },
    Bulk,
}

enum Flow {
    Continue,
    End,
}

/// The card being read: it may still be continued.
struct Open {
    card: RawCard,
    /// Field 10 of its last line.
    marker: String,
    marker_loc: Loc,
}

struct DeckReader<'a, 's> {
    limits: &'a DeckLimits,
    /// Canonical folder every file must lie in (`None`: text in memory, no INCLUDE).
    root: Option<PathBuf>,
    /// Canonical folder of the deck itself (included files are named relative to it).
    top_dir: Option<PathBuf>,
    stack: Vec<Source<'a>>,
    digests: Vec<(String, Option<String>)>,
    sink: &'s mut dyn CardSink,
    mode: Mode,
    open: Option<Open>,
    cards: usize,
    spc_selection: Option<u32>,
    sdamping: Option<(u32, Loc)>,
    /// First error of the bulk-data reading of lines before a `BEGIN BULK` that may follow.
    tentative_error: Option<FeError>,
    /// First error of the control reading of the same lines.
    control_error: Option<FeError>,
    first_include: Option<Loc>,
    peak_line_bytes: usize,
    /// Whether files are hashed for the digest.
    hash: bool,
}

fn io_error(source: &Source, e: std::io::Error) -> FeError {
    FeError::Io(format!("reading {}: {e}", source.label))
}

fn starts_with_word(text: &str, word: &str) -> bool {
    text.len() >= word.len() && text.as_bytes()[..word.len()].eq_ignore_ascii_case(word.as_bytes())
}

/// The marker without its leading `+` or `*`.
fn marker_key(marker: &str) -> &str {
    marker
        .strip_prefix(['+', '*'])
        .unwrap_or(marker)
        .trim_start()
}

impl<'a, 's> DeckReader<'a, 's> {
    fn new(limits: &'a DeckLimits, sink: &'s mut dyn CardSink) -> Self {
        Self {
            limits,
            root: None,
            top_dir: None,
            stack: Vec::new(),
            digests: Vec::new(),
            sink,
            mode: Mode::Unknown { bulk_ended: false },
            open: None,
            cards: 0,
            spc_selection: None,
            sdamping: None,
            tentative_error: None,
            control_error: None,
            first_include: None,
            peak_line_bytes: 0,
            hash: false,
        }
    }

    fn push(&mut self, mut source: Source<'a>) {
        source.slot = self.digests.len();
        self.digests.push((source.label.clone(), None));
        self.stack.push(source);
    }

    fn pop(&mut self) {
        if let Some(source) = self.stack.pop() {
            let hasher = source.reader.into_inner().hasher;
            self.digests[source.slot].1 = hasher.map(|h| hex(&h.finalize()));
        }
    }

    fn run(mut self) -> Result<DeckInfo, FeError> {
        let mut buf = Vec::new();
        let cap = self.limits.max_line_bytes;
        while let Some(source) = self.stack.last_mut() {
            let read = read_line_capped(&mut source.reader, &mut buf, cap)
                .map_err(|e| io_error(source, e))?;
            self.peak_line_bytes = self.peak_line_bytes.max(buf.capacity());
            if matches!(read, LineRead::Eof) {
                self.pop();
                continue;
            }
            source.line += 1;
            let loc = Loc {
                line: source.line,
                file: source.name.clone(),
            };
            match read {
                LineRead::TooLong => {
                    return Err(lex_error(
                        &loc,
                        format!(
                            "the line is longer than the {cap} bytes allowed for one line \
                             (DeckLimits::max_line_bytes); is this a bulk data deck?"
                        ),
                    ))
                }
                LineRead::Nul(column) => {
                    return Err(lex_error(
                        &loc,
                        format!(
                            "binary data (a NUL byte in column {column}): not a text bulk data \
                             deck"
                        ),
                    ))
                }
                _ => {}
            }
            let text = std::str::from_utf8(&buf)
                .map_err(|_| lex_error(&loc, "not UTF-8 text: not a text bulk data deck"))?;
            let control = |c: &char| c.is_control() && !matches!(c, '\t' | '\r' | '\x0c');
            let ascii_clean = buf
                .iter()
                .all(|&b| (b >= 0x20 && b != 0x7f) || matches!(b, b'\t' | b'\r' | 0x0c));
            if let Some((column, c)) = (!ascii_clean)
                .then(|| text.chars().enumerate().find(|(_, c)| control(c)))
                .flatten()
            {
                return Err(lex_error(
                    &loc,
                    format!(
                        "control character U+{:04X} in column {}: not a text bulk data deck",
                        c as u32,
                        column + 1
                    ),
                ));
            }
            if let Flow::End = self.line(text.trim_end_matches('\r'), loc)? {
                if !self.hash {
                    self.stack.clear();
                }
                // The rest of every open file is not bulk data, but the digest covers whole
                // files.
                while let Some(source) = self.stack.last_mut() {
                    std::io::copy(&mut source.reader, &mut std::io::sink())
                        .map_err(|e| io_error(source, e))?;
                    self.pop();
                }
            }
        }
        self.finish()
    }

    fn finish(mut self) -> Result<DeckInfo, FeError> {
        match self.mode {
            Mode::Bulk => self.end_of_bulk(None)?,
            Mode::Unknown { bulk_ended } => {
                // No BEGIN BULK: everything was bulk data.
                if let Some(e) = self.tentative_error.take() {
                    return Err(e);
                }
                if !bulk_ended {
                    self.end_of_bulk(None)?;
                }
                self.spc_selection = None;
                self.sdamping = None;
            }
        }
        let sha256 = match self.digests.as_slice() {
            _ if !self.hash => String::new(),
            [(_, Some(one))] => one.clone(),
            all => {
                let mut h = Sha256::new();
                for (label, digest) in all {
                    h.update(label.as_bytes());
                    h.update([0]);
                    h.update(digest.as_deref().unwrap_or("").as_bytes());
                    h.update(b"\n");
                }
                hex(&h.finalize())
            }
        };
        Ok(DeckInfo {
            spc_selection: self.spc_selection,
            sdamping: self.sdamping,
            sha256,
            peak_line_bytes: self.peak_line_bytes,
        })
    }

    fn line(&mut self, raw: &str, loc: Loc) -> Result<Flow, FeError> {
        let Mode::Unknown { bulk_ended } = self.mode else {
            return self.bulk_line(raw, loc);
        };
        if strip_comment(raw).trim().is_empty() {
            return Ok(Flow::Continue);
        }
        if is_begin_bulk(raw) {
            if loc.file.is_some() {
                return Err(lex_error(
                    &loc,
                    "BEGIN BULK in an included file: put it in the deck itself",
                ));
            }
            if let Some(e) = self.control_error.take() {
                return Err(e);
            }
            if let Some(at) = &self.first_include {
                return Err(lex_error(
                    at,
                    "INCLUDE before BEGIN BULK is not supported (executive and case control are \
                     read only for SPC = n and SDAMPING = n); move the INCLUDE into the bulk \
                     data",
                ));
            }
            self.sink.reset();
            self.open = None;
            self.cards = 0;
            self.tentative_error = None;
            self.mode = Mode::Bulk;
            return Ok(Flow::Continue);
        }
        if self.control_error.is_none() {
            match case_control_spc(raw, &loc) {
                Ok(Some(set)) if self.spc_selection.is_some_and(|s| s != set) => {
                    self.control_error = Some(lex_error(
                        &loc,
                        "subcases select different SPC sets; one body needs one set of supports",
                    ));
                }
                Ok(Some(set)) => self.spc_selection = Some(set),
                Ok(None) => {}
                Err(e) => self.control_error = Some(e),
            }
        }
        if self.control_error.is_none() {
            match case_control_sdamping(raw, &loc) {
                Ok(Some(id)) if self.sdamping.as_ref().is_some_and(|(s, _)| *s != id) => {
                    self.control_error = Some(lex_error(
                        &loc,
                        "subcases select different SDAMPING tables; one body has one modal \
                         damping",
                    ));
                }
                Ok(Some(id)) => self.sdamping = Some((id, loc.clone())),
                Ok(None) => {}
                Err(e) => self.control_error = Some(e),
            }
        }
        if self.first_include.is_none() && starts_with_word(raw.trim_start(), "INCLUDE") {
            self.first_include = Some(loc.clone());
        }
        if !bulk_ended && self.tentative_error.is_none() {
            match self.bulk_line(raw, loc) {
                Ok(Flow::End) => self.mode = Mode::Unknown { bulk_ended: true },
                Ok(Flow::Continue) => {}
                Err(e) => self.tentative_error = Some(e),
            }
        }
        Ok(Flow::Continue)
    }

    /// One physical line of bulk data: ENDDATA, an INCLUDE, or a line of a card (its fields in
    /// small, large or free format; a continuation, or the start of the next card, which hands the
    /// card before it to the sink).
    ///
    /// Long on purpose: the line formats share the limits (fields per card, cards, line length) and
    /// the pending card they add to; split by format, each piece would need the whole reader state.
    fn bulk_line(&mut self, raw: &str, loc: Loc) -> Result<Flow, FeError> {
        let line = strip_comment(raw);
        let head = line.trim_start();
        if head.is_empty() {
            return Ok(Flow::Continue);
        }
        if starts_with_word(head, "ENDDATA") {
            self.end_of_bulk(Some(&loc))?;
            return Ok(Flow::End);
        }
        if starts_with_word(head, "INCLUDE") {
            if let Some(open) = self.open.as_ref().filter(|o| !o.marker.is_empty()) {
                return Err(lex_error(
                    &loc,
                    format!(
                        "the {} card at line {} ends with the continuation marker '{}' but an \
                         INCLUDE follows: a card cannot continue across an INCLUDE",
                        open.card.name,
                        open.card.loc(),
                        shown(&open.marker)
                    ),
                ));
            }
            self.flush()?;
            self.include(raw, loc)?;
            return Ok(Flow::Continue);
        }
        if !line.is_ascii() {
            return Err(lex_error(&loc, "non-ASCII character in bulk data"));
        }
        let split = split_line(line, &loc)?;
        let n_fields = split.fields.len();
        let fields = split.fields.into_iter().map(|(text, position)| Field {
            text,
            line: loc.line,
            position,
        });
        let first = split.first;
        if first.is_empty() || first.starts_with(['+', '*']) {
            let Some(open) = self.open.as_mut() else {
                return Err(lex_error(
                    &loc,
                    "continuation line without a card before it",
                ));
            };
            if open.card.file != loc.file {
                return Err(lex_error(
                    &loc,
                    format!(
                        "continuation line in another file than its {} card (line {}): a card \
                         cannot continue across an INCLUDE",
                        open.card.name,
                        open.card.loc()
                    ),
                ));
            }
            let wanted = marker_key(&first);
            if !wanted.is_empty() && wanted != marker_key(&open.marker) {
                let have = if open.marker.is_empty() {
                    "a blank continuation field".to_owned()
                } else {
                    format!("the continuation marker '{}'", shown(&open.marker))
                };
                return Err(lex_error(
                    &loc,
                    format!(
                        "continuation marker '{}' does not match {have} of the {} card at line \
                         {} (field 10 of line {})",
                        shown(&first),
                        open.card.name,
                        open.card.loc(),
                        open.marker_loc
                    ),
                ));
            }
            if open.card.fields.len() + n_fields > self.limits.max_card_fields {
                return Err(lex_error(
                    &loc,
                    format!(
                        "the {} card at line {} has more than {} fields \
                         (DeckLimits::max_card_fields)",
                        open.card.name,
                        open.card.loc(),
                        self.limits.max_card_fields
                    ),
                ));
            }
            open.card.fields.extend(fields);
            open.marker = split.marker;
            open.marker_loc = loc;
        } else {
            let name = first.trim_end_matches('*').to_string();
            if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric()) {
                return Err(lex_error(
                    &loc,
                    format!("'{}' is not a card name", shown(&first)),
                ));
            }
            self.flush()?;
            self.cards += 1;
            if self.cards > self.limits.max_cards {
                return Err(lex_error(
                    &loc,
                    format!(
                        "more than {} cards: the model exceeds DeckLimits::max_cards",
                        self.limits.max_cards
                    ),
                ));
            }
            self.open = Some(Open {
                card: RawCard {
                    name,
                    line: loc.line,
                    file: loc.file.clone(),
                    fields: fields.collect(),
                },
                marker: split.marker,
                marker_loc: loc,
            });
        }
        Ok(Flow::Continue)
    }

    /// Hands the card being read to the sink.
    fn flush(&mut self) -> Result<(), FeError> {
        if let Some(Open { mut card, .. }) = self.open.take() {
            while card.fields.last().is_some_and(|f| f.text.is_empty()) {
                card.fields.pop();
            }
            self.sink.card(card)?;
        }
        Ok(())
    }

    /// ENDDATA (`at`) or the end of the deck: the last card must not wait for a continuation.
    fn end_of_bulk(&mut self, at: Option<&Loc>) -> Result<(), FeError> {
        if let Some(open) = &self.open {
            if !open.marker.is_empty() {
                let end = match at {
                    Some(loc) => format!("ENDDATA follows at line {loc}"),
                    None => "the deck ends".to_owned(),
                };
                return Err(lex_error(
                    &open.marker_loc,
                    format!(
                        "the {} card at line {} ends with the continuation marker '{}' but \
                         {end} without its continuation line",
                        open.card.name,
                        open.card.loc(),
                        shown(&open.marker)
                    ),
                ));
            }
        }
        self.flush()
    }

    /// The file name of an INCLUDE statement: quoted (`'…'`, possibly continued over lines) or
    /// a single unquoted word.
    fn include_name(&mut self, raw: &str, loc: &Loc) -> Result<String, FeError> {
        const MAX_NAME: usize = 4096;
        let rest = raw.trim_start()[7..].trim();
        let Some(quoted) = rest.strip_prefix('\'') else {
            let word = strip_comment(rest).trim();
            if word.is_empty() || word.contains(char::is_whitespace) {
                return Err(lex_error(
                    loc,
                    "INCLUDE needs one file name, written INCLUDE 'file'",
                ));
            }
            return Ok(word.to_owned());
        };
        let mut name = String::new();
        let mut piece = quoted.to_owned();
        let mut buf = Vec::new();
        loop {
            if let Some(end) = piece.find('\'') {
                name.push_str(piece[..end].trim());
                let after = piece[end + 1..].trim();
                if !(after.is_empty() || after.starts_with('$')) {
                    return Err(lex_error(
                        loc,
                        format!(
                            "unexpected text '{}' after INCLUDE's file name",
                            shown(after)
                        ),
                    ));
                }
                break;
            }
            name.push_str(piece.trim());
            if name.len() > MAX_NAME {
                return Err(lex_error(
                    loc,
                    format!("INCLUDE file name longer than {MAX_NAME} characters"),
                ));
            }
            let Some(source) = self.stack.last_mut() else {
                break;
            };
            let read = read_line_capped(&mut source.reader, &mut buf, self.limits.max_line_bytes)
                .map_err(|e| io_error(source, e))?;
            if !matches!(read, LineRead::Line) {
                return Err(lex_error(
                    loc,
                    "INCLUDE's quoted file name is not closed by a quote",
                ));
            }
            source.line += 1;
            piece = String::from_utf8(std::mem::take(&mut buf)).map_err(|_| {
                lex_error(
                    loc,
                    "INCLUDE's file name continues on a line that is not UTF-8",
                )
            })?;
            piece = piece.trim_end_matches('\r').to_owned();
        }
        if name.is_empty() {
            return Err(lex_error(loc, "INCLUDE with an empty file name"));
        }
        Ok(name)
    }

    fn chain(&self, last: &str) -> String {
        let mut labels: Vec<&str> = self.stack.iter().map(|s| s.label.as_str()).collect();
        labels.push(last);
        labels.join(" → ")
    }

    /// `INCLUDE 'file'`: the file read in place, after the checks that keep it inside the include
    /// root (resolved path, no `..` or symbolic link out), refuse cycles and too deep nesting, and
    /// count it against the card limit.
    ///
    /// Long on purpose: the checks run in this order on one resolved path, each refusal naming the
    /// include chain; the file is then pushed on the same stack the checks read.
    fn include(&mut self, raw: &str, loc: Loc) -> Result<(), FeError> {
        // Counted like a card: a deck of endless INCLUDE lines is bounded like one of cards.
        self.cards += 1;
        if self.cards > self.limits.max_cards {
            return Err(lex_error(
                &loc,
                format!(
                    "more than {} cards and INCLUDEs: the model exceeds DeckLimits::max_cards",
                    self.limits.max_cards
                ),
            ));
        }
        let name = self.include_name(raw, &loc)?;
        let (Some(root), Some(dir)) = (
            self.root.clone(),
            self.stack
                .last()
                .and_then(|s| s.path.as_deref())
                .and_then(Path::parent),
        ) else {
            return Err(lex_error(
                &loc,
                "INCLUDE needs a deck read from a file (this bulk data is text in memory)",
            ));
        };
        let target = dir.join(&name);
        let path = std::fs::canonicalize(&target).map_err(|e| {
            lex_error(
                &loc,
                format!("INCLUDE '{name}': cannot open {}: {e}", target.display()),
            )
        })?;
        if !path.starts_with(&root) {
            return Err(lex_error(
                &loc,
                format!(
                    "INCLUDE '{name}' is {}, outside {}, the folder decks are confined to (the \
                     vehicle JSON's body.include_root allows another)",
                    path.display(),
                    root.display()
                ),
            ));
        }
        let label = match self
            .top_dir
            .as_deref()
            .and_then(|d| path.strip_prefix(d).ok())
        {
            Some(relative) => relative.display().to_string(),
            None => path.display().to_string(),
        };
        if self
            .stack
            .iter()
            .any(|s| s.path.as_deref() == Some(path.as_path()))
        {
            return Err(lex_error(
                &loc,
                format!("INCLUDE cycle: {}", self.chain(&label)),
            ));
        }
        if self.stack.len() > self.limits.max_include_depth {
            return Err(lex_error(
                &loc,
                format!(
                    "INCLUDE nested deeper than {} files (DeckLimits::max_include_depth): {}",
                    self.limits.max_include_depth,
                    self.chain(&label)
                ),
            ));
        }
        let file = open_regular(&path).map_err(|m| lex_error(&loc, format!("INCLUDE: {m}")))?;
        let mut source = Source::new(
            Box::new(file),
            Some(label.as_str().into()),
            label,
            self.hash,
        );
        source.path = Some(path);
        self.push(source);
        Ok(())
    }
}

/// Opens `path` if it is a regular file (checked first: opening a FIFO would block).
fn open_regular(path: &Path) -> Result<File, String> {
    let meta =
        std::fs::metadata(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!(
            "{} is not a regular file (a directory, FIFO or device cannot be read as a deck)",
            path.display()
        ));
    }
    File::open(path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

/// Reads bulk data from text in memory (no INCLUDE).
pub(crate) fn read_text(
    text: &str,
    limits: &DeckLimits,
    sink: &mut dyn CardSink,
) -> Result<DeckInfo, FeError> {
    read_from(text.as_bytes(), limits, sink)
}

/// Reads bulk data from any reader (no INCLUDE): the deck is never held in memory whole.
pub(crate) fn read_from<'a>(
    input: impl Read + 'a,
    limits: &DeckLimits,
    sink: &mut dyn CardSink,
) -> Result<DeckInfo, FeError> {
    let mut reader = DeckReader::new(limits, sink);
    reader.push(Source::new(Box::new(input), None, "deck".into(), false));
    reader.run()
}

/// Reads the deck file `path` and its INCLUDEs.
pub(crate) fn read_file(
    path: &Path,
    options: &DeckOptions,
    sink: &mut dyn CardSink,
    hash: bool,
) -> Result<DeckInfo, FeError> {
    let io = |m: String| FeError::Io(format!("bulk data file: {m}"));
    let file = open_regular(path).map_err(io)?;
    let canonical = std::fs::canonicalize(path)
        .map_err(|e| io(format!("cannot read {}: {e}", path.display())))?;
    let top_dir = canonical
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let root = match &options.include_root {
        None => top_dir.clone(),
        Some(root) => std::fs::canonicalize(root).map_err(|e| {
            io(format!(
                "include root {} cannot be used: {e}",
                root.display()
            ))
        })?,
    };
    if !canonical.starts_with(&root) {
        return Err(io(format!(
            "{} is outside {}, the folder decks are confined to",
            canonical.display(),
            root.display()
        )));
    }
    let label = canonical
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string());
    let mut reader = DeckReader::new(&options.limits, sink);
    reader.root = Some(root);
    reader.hash = hash;
    reader.top_dir = Some(top_dir);
    let mut source = Source::new(Box::new(file), None, label, hash);
    source.path = Some(canonical);
    reader.push(source);
    reader.run()
}

/// Discards cards: reading only for the digest and the lexical checks.
pub(crate) struct Discard;

impl CardSink for Discard {
    fn card(&mut self, _: RawCard) -> Result<(), FeError> {
        Ok(())
    }

    fn reset(&mut self) {}
}
/// Splits `text` into cards (an in-memory deck: `INCLUDE` is refused, there is no folder to
/// resolve it against).
pub fn lex(text: &str) -> Result<Deck, FeError> {
    let mut cards: Vec<RawCard> = Vec::new();
    let info = read_text(text, &DeckLimits::default(), &mut cards)?;
    Ok(Deck {
        cards,
        spc_selection: info.spc_selection,
    })
}
