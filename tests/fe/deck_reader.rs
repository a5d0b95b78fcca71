//! The streaming bulk-deck reader on bad and large input (issue 28) and INCLUDE (issue 27):
//! memory that does not follow line or file length, binary junk, continuation markers, INCLUDE
//! confinement, cycles and depth, the deck digest, and decks that are not decks.

use std::io::Read;
use std::path::{Path, PathBuf};

use engine_mount_chassis::cms::sha256_hex;
use engine_mount_chassis::nastran::{
    deck_digest, lex_reader_peak_line_bytes, parse_reader, parse_str, read_bulk_deck,
    read_bulk_deck_with, DeckLimits, DeckOptions,
};

/// A fresh folder for one test's files.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("emc-deck-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(path: &Path, text: &str) {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).unwrap();
    }
    std::fs::write(path, text).unwrap();
}

/// Counts the bytes pulled from the inner reader.
struct Counting<R> {
    inner: R,
    pulled: std::rc::Rc<std::cell::Cell<u64>>,
}

impl<R: Read> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.pulled.set(self.pulled.get() + n as u64);
        Ok(n)
    }
}

fn counting<R: Read>(inner: R) -> (Counting<R>, std::rc::Rc<std::cell::Cell<u64>>) {
    let pulled = std::rc::Rc::new(std::cell::Cell::new(0));
    (
        Counting {
            inner,
            pulled: pulled.clone(),
        },
        pulled,
    )
}

/// `total` bytes of comment lines of `width` bytes each, generated as they are read.
struct Comments {
    line: Vec<u8>,
    at: usize,
    left: u64,
}

impl Comments {
    fn new(width: usize, total: u64) -> Self {
        let mut line = vec![b'$'; 1];
        line.resize(width - 1, b'x');
        line.push(b'\n');
        Self {
            line,
            at: 0,
            left: total,
        }
    }
}

impl Read for Comments {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let mut n = 0;
        while n < buf.len() && self.left > 0 {
            let chunk = (self.line.len() - self.at)
                .min(buf.len() - n)
                .min(self.left as usize);
            buf[n..n + chunk].copy_from_slice(&self.line[self.at..self.at + chunk]);
            self.at = (self.at + chunk) % self.line.len();
            self.left -= chunk as u64;
            n += chunk;
        }
        Ok(n)
    }
}

const SPRING: &str = "GRID,1,,0.,0.,0.\nCONM2,2,1,,1.\nCELAS2,3,100.,1,1\n";

#[test]
fn two_hundred_megabytes_of_comments_read_in_one_line_of_memory() {
    let total = 200u64 << 20;
    let (input, pulled) = counting(Comments::new(80, total).chain(SPRING.as_bytes()));
    let peak = lex_reader_peak_line_bytes(input, &DeckLimits::default()).unwrap();
    assert_eq!(pulled.get(), total + SPRING.len() as u64);
    assert!(peak <= 256, "line buffer grew to {peak} bytes");
    // Lines just under the cap: the buffer stays at the cap, whatever the file length.
    let limits = DeckLimits::default();
    let wide = Comments::new(limits.max_line_bytes, 50 << 20);
    let peak = lex_reader_peak_line_bytes(wide, &limits).unwrap();
    assert!(peak <= 2 * limits.max_line_bytes, "{peak}");
}

#[test]
fn an_endless_line_is_refused_after_reading_the_cap() {
    let limits = DeckLimits {
        max_line_bytes: 1000,
        ..DeckLimits::default()
    };
    // 100 MB on one line (here: endless) after two good lines.
    let (input, pulled) = counting((&SPRING.as_bytes()[..17]).chain(std::io::repeat(b'x')));
    let err = parse_reader(input, &limits).unwrap_err().to_string();
    assert!(
        err.contains("line 2") && err.contains("longer than the 1000 bytes"),
        "{err}"
    );
    // What the BufReader had buffered beyond the cap, no more.
    assert!(pulled.get() <= 1000 + (64 << 10) + 17, "{}", pulled.get());
}

#[test]
fn binary_junk_is_refused_at_its_line_without_reading_on() {
    let (input, pulled) = counting(std::io::repeat(0u8));
    let err = parse_reader(input, &DeckLimits::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 1") && err.contains("NUL byte"), "{err}");
    assert!(pulled.get() <= 64 << 10, "{}", pulled.get());
    let dir = folder("nul");
    let deck = dir.join("junk.bdf");
    std::fs::write(&deck, vec![0u8; 1 << 20]).unwrap();
    let err = read_bulk_deck(&deck).unwrap_err().to_string();
    assert!(
        err.contains("junk.bdf") && err.contains("line 1") && err.contains("binary data"),
        "{err}"
    );
    let err = parse_str("GRID,1,,0.,0.,0.\nGR\x07ID,2\n")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("line 2") && err.contains("control character"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_model_size_is_checked_against_the_stated_limits() {
    let limits = DeckLimits {
        max_cards: 2,
        ..DeckLimits::default()
    };
    let err = parse_reader(SPRING.as_bytes(), &limits)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("line 3") && err.contains("more than 2 cards"),
        "{err}"
    );
    assert!(parse_reader(SPRING.as_bytes(), &DeckLimits::default()).is_ok());
    let limits = DeckLimits {
        max_card_fields: 20,
        ..DeckLimits::default()
    };
    let long = format!("SPC1,1,123456,1\n{}", ",1,1,1,1,1,1,1,1\n".repeat(3));
    let err = parse_reader(long.as_bytes(), &limits)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("line 3") && err.contains("SPC1") && err.contains("more than 20 fields"),
        "{err}"
    );
}

#[test]
fn continuation_markers_must_match_and_none_may_dangle() {
    let ok = "BEGIN BULK\nGRID,1,,0.,0.,0.\nCONM2,2,1,,1.,,,,,+M1\n+M1,0.1,,0.2,,,0.3\n";
    let body = parse_str(ok).unwrap();
    assert_eq!(body.mesh.masses.len(), 1);
    let err = parse_str(&ok.replace("+M1,0.1", "+M2,0.1"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("line 4") && err.contains("'+M2'") && err.contains("'+M1'"),
        "{err}"
    );
    // Fixed field: field 10 in columns 73-80.
    let fixed = format!(
        "{:<8}{:>8}{:>8}{:>8}{:>8}{:>8}{:24}{:<8}\n+G2\n",
        "GRID", "1", "", "0.", "0.", "0.", "", "+G1"
    );
    let err = parse_str(&fixed).unwrap_err().to_string();
    assert!(err.contains("line 2") && err.contains("'+G2'"), "{err}");
    let err = parse_str("GRID,1,,0.,0.,0.\n+A,1\n")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("line 2") && err.contains("blank continuation field"),
        "{err}"
    );
    // A continuation marker on the last card with nothing after it.
    let err = parse_str("GRID,1,,0.,0.,0.,,,,+\n")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("line 1") && err.contains("the deck ends"),
        "{err}"
    );
    let err = parse_str("GRID,1,,0.,0.,0.,,,,+G\nENDDATA\n")
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 1") && err.contains("ENDDATA"), "{err}");
}

/// The spring-mass deck split over files: `main.bdf` includes `sub/grid.bdf` (quoted name
/// continued over two lines) and `sub/mass.bdf` (unquoted).
fn split_deck(dir: &Path) -> PathBuf {
    let main = dir.join("main.bdf");
    write(
        &main,
        "SOL 103\nCEND\nBEGIN BULK\nINCLUDE 'sub/\n   grid.bdf'\nINCLUDE sub/mass.bdf\n\
         CELAS2,3,100.,1,1\nENDDATA\n",
    );
    write(&dir.join("sub/grid.bdf"), "$ the grid\nGRID,1,,0.,0.,0.\n");
    write(&dir.join("sub/mass.bdf"), "CONM2,2,1,,1.\n");
    main
}

#[test]
fn include_reads_files_relative_to_the_including_one() {
    let dir = folder("include");
    let main = split_deck(&dir);
    let whole = parse_str(SPRING).unwrap();
    let (body, digest) = read_bulk_deck_with(&main, &DeckOptions::default()).unwrap();
    assert_eq!(body.mesh, whole.mesh);
    assert_eq!(digest, deck_digest(&main, &DeckOptions::default()).unwrap());
    // The digest follows an included file's content.
    write(&dir.join("sub/mass.bdf"), "CONM2,2,1,,2.\n");
    let changed = deck_digest(&main, &DeckOptions::default()).unwrap();
    assert_ne!(changed, digest);
    // An error inside an included file names that file and its line.
    write(&dir.join("sub/mass.bdf"), "$ mass\nCONM2,2,1,,1\n");
    let err = read_bulk_deck(&main).unwrap_err().to_string();
    assert!(
        err.contains("main.bdf") && err.contains("line 2 of sub/mass.bdf"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_deck_without_includes_has_the_sha256_of_its_file_as_digest() {
    let dir = folder("digest");
    let deck = dir.join("d.bdf");
    let text = format!("{SPRING}ENDDATA\ntrailing text after ENDDATA\n");
    write(&deck, &text);
    assert_eq!(
        deck_digest(&deck, &DeckOptions::default()).unwrap(),
        sha256_hex(text.as_bytes())
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn include_is_confined_to_the_decks_folder_unless_a_root_allows_more() {
    let dir = folder("confine");
    let inner = dir.join("model");
    let main = inner.join("main.bdf");
    write(&main, "GRID,1,,0.,0.,0.\nINCLUDE '../shared/mass.bdf'\n");
    write(&dir.join("shared/mass.bdf"), "CONM2,2,1,,1.\n");
    let err = read_bulk_deck(&main).unwrap_err().to_string();
    assert!(
        err.contains("line 2") && err.contains("outside") && err.contains("include_root"),
        "{err}"
    );
    let options = DeckOptions {
        include_root: Some(dir.clone()),
        ..DeckOptions::default()
    };
    let (body, _) = read_bulk_deck_with(&main, &options).unwrap();
    assert_eq!(body.mesh.masses.len(), 1);
    // The deck itself must lie in the root too.
    let options = DeckOptions {
        include_root: Some(dir.join("shared")),
        ..DeckOptions::default()
    };
    let err = read_bulk_deck_with(&main, &options)
        .unwrap_err()
        .to_string();
    assert!(err.contains("outside"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn include_cycles_and_depth_are_refused_with_the_chain() {
    let dir = folder("cycle");
    write(&dir.join("a.bdf"), "GRID,1,,0.,0.,0.\nINCLUDE 'b.bdf'\n");
    write(&dir.join("b.bdf"), "$ b\n\nINCLUDE 'a.bdf'\n");
    let err = read_bulk_deck(&dir.join("a.bdf")).unwrap_err().to_string();
    assert!(
        err.contains("line 3 of b.bdf") && err.contains("a.bdf → b.bdf → a.bdf"),
        "{err}"
    );
    for k in 0..5 {
        write(
            &dir.join(format!("n{k}.bdf")),
            &format!("INCLUDE 'n{}.bdf'\n", k + 1),
        );
    }
    write(&dir.join("n5.bdf"), "GRID,1,,0.,0.,0.\n");
    let limits = DeckLimits {
        max_include_depth: 4,
        ..DeckLimits::default()
    };
    let options = DeckOptions {
        limits,
        ..DeckOptions::default()
    };
    let err = read_bulk_deck_with(&dir.join("n0.bdf"), &options)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("deeper than 4") && err.contains("n0.bdf → n1.bdf → n2.bdf"),
        "{err}"
    );
    assert!(read_bulk_deck(&dir.join("n0.bdf")).is_ok());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn include_before_begin_bulk_and_include_in_memory_are_refused() {
    let dir = folder("early");
    let main = dir.join("main.bdf");
    write(
        &main,
        "SOL 103\nINCLUDE 'x.bdf'\nCEND\nBEGIN BULK\nGRID,1,,0.,0.,0.\n",
    );
    write(&dir.join("x.bdf"), "GRID,2,,0.,0.,0.\n");
    let err = read_bulk_deck(&main).unwrap_err().to_string();
    assert!(
        err.contains("line 2") && err.contains("INCLUDE before BEGIN BULK"),
        "{err}"
    );
    let err = parse_str("GRID,1,,0.,0.,0.\nINCLUDE 'x.bdf'\n")
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 2") && err.contains("INCLUDE"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_file_that_is_not_a_deck_is_not_echoed() {
    let dir = folder("passwd");
    let secret = dir.join("secret.txt");
    write(
        &secret,
        "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1::/usr/sbin:/usr/sbin/nologin\n",
    );
    let err = read_bulk_deck(&secret).unwrap_err().to_string();
    assert!(
        err.contains("line 1") && err.contains("not a card name"),
        "{err}"
    );
    assert!(
        !err.contains("/bin/bash") && !err.contains("ROOT:X:0:0"),
        "{err}"
    );
    // A vehicle configuration naming a deck outside its folder is refused before reading it.
    let config_dir = dir.join("config");
    std::fs::create_dir_all(&config_dir).unwrap();
    let mut vehicle: serde_json::Value =
        serde_json::from_str(&engine_mount_chassis::model::VehicleConfig::default().to_json())
            .unwrap();
    vehicle["body"] = serde_json::json!({
        "kind": "nastran",
        "path": "../secret.txt",
        "points": {}
    });
    let json = config_dir.join("vehicle.json");
    std::fs::write(&json, vehicle.to_string()).unwrap();
    let err = engine_mount_chassis::model::VehicleConfig::from_file(&json)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("body.path") && err.contains("outside") && !err.contains("root:"),
        "{err}"
    );
    // include_root (relative to the configuration) allows the folder above.
    vehicle["body"]["include_root"] = serde_json::json!("..");
    std::fs::write(&json, vehicle.to_string()).unwrap();
    let config = engine_mount_chassis::model::VehicleConfig::from_file(&json).unwrap();
    match config.body {
        engine_mount_chassis::model::BodyConfig::Nastran { include_root, .. } => {
            assert_eq!(include_root, Some(config_dir.join("..")));
        }
        other => panic!("{other:?}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn symbolic_links_out_of_the_root_and_cards_across_files_are_refused() {
    let dir = folder("links");
    let model = dir.join("model");
    write(&dir.join("outside.bdf"), "CONM2,2,1,,1.\n");
    std::fs::create_dir_all(&model).unwrap();
    std::os::unix::fs::symlink(dir.join("outside.bdf"), model.join("link.bdf")).unwrap();
    let main = model.join("main.bdf");
    write(&main, "GRID,1,,0.,0.,0.\nINCLUDE 'link.bdf'\n");
    let err = read_bulk_deck(&main).unwrap_err().to_string();
    assert!(err.contains("line 2") && err.contains("outside"), "{err}");
    // A card may not continue in another file, and BEGIN BULK belongs to the deck itself.
    write(&model.join("tail.bdf"), "+M1,0.1,,0.2,,,0.3\n");
    write(
        &main,
        "GRID,1,,0.,0.,0.\nCONM2,2,1,,1.,,,,,+M1\nINCLUDE 'tail.bdf'\n",
    );
    let err = read_bulk_deck(&main).unwrap_err().to_string();
    assert!(
        err.contains("line 3") && err.contains("'+M1'") && err.contains("across an INCLUDE"),
        "{err}"
    );
    write(&model.join("tail.bdf"), "CONM2,2,1,,1.\n");
    write(
        &main,
        "GRID,1,,0.,0.,0.\nINCLUDE 'tail.bdf'\n,0.1,,0.2,,,0.3\n",
    );
    let err = read_bulk_deck(&main).unwrap_err().to_string();
    assert!(
        err.contains("line 3") && err.contains("line 1 of tail.bdf") && err.contains("across"),
        "{err}"
    );
    write(&model.join("bulk.bdf"), "BEGIN BULK\nCONM2,2,1,,1.\n");
    write(&main, "GRID,1,,0.,0.,0.\nINCLUDE 'bulk.bdf'\n");
    let err = read_bulk_deck(&main).unwrap_err().to_string();
    assert!(
        err.contains("line 1 of bulk.bdf") && err.contains("BEGIN BULK"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
