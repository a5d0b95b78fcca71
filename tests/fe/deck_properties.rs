//! Properties of the bulk-deck lexer and parser: no input makes them panic (errors only), and
//! decks written by `write_bulk_deck` from random small meshes read back to the same mesh.

use std::fmt::Write;

use engine_mount_chassis::nastran::{lex, parse_reader, parse_str, write_bulk_deck, DeckLimits};
use proptest::prelude::*;

/// Pieces that bulk data is made of, so random decks reach deep into the lexer and the card
/// readers instead of failing on the first byte.
const TOKENS: [&str; 40] = [
    "GRID",
    "CONM2",
    "CELAS2",
    "CBAR",
    "PBAR",
    "MAT1",
    "PSHELL",
    "CQUAD4",
    "CTRIA3",
    "RBE2",
    "RBE3",
    "SPC1",
    "SPC",
    "CORD2R",
    "PARAM",
    "WTMASS",
    "INCLUDE",
    "'x.bdf'",
    "BEGIN BULK",
    "ENDDATA",
    "CEND",
    "SPC = 1",
    "THRU",
    "+",
    "+C1",
    "*",
    "GRID*",
    ",",
    ",",
    ",",
    "\n",
    "\n",
    "\t",
    " ",
    "$ c",
    "1",
    "2.5",
    "-1.-3",
    "1.E3",
    "0.",
];

fn token_deck() -> impl Strategy<Value = String> {
    prop::collection::vec(
        prop_oneof![
            4 => (0..TOKENS.len()).prop_map(|i| TOKENS[i].to_string()),
            1 => "[ -~]{0,12}",
            1 => (1u32..40).prop_map(|n| n.to_string()),
        ],
        0..120,
    )
    .prop_map(|parts| parts.concat())
}

/// A small random body in free field: grids, shells, triangles, beams, masses, springs,
/// supports.
fn random_deck() -> impl Strategy<Value = String> {
    (
        prop::collection::vec(prop::array::uniform3(-2.0f64..2.0), 4..10),
        prop::collection::vec((0usize..100, 0usize..100, 0usize..100, 0usize..100), 0..4),
        prop::collection::vec((0usize..100, 0usize..100, 0usize..100), 0..4),
        prop::collection::vec((0usize..100, 0usize..100), 0..4),
        prop::collection::vec((0usize..100, 0.1f64..10.0), 0..3),
        prop::collection::vec((0usize..100, 1usize..7, 1.0e3f64..1.0e6), 0..3),
        (1.0e-3f64..1.0e-2, 0usize..100),
    )
        .prop_map(|(nodes, quads, tris, bars, masses, springs, (t, fixed))| {
            let n = nodes.len();
            let mut deck = String::from("BEGIN BULK\nMAT1,1,2.1+11,,0.3,7850.\n");
            let _ = writeln!(deck, "PSHELL,7,1,{t:.4e},1,,1");
            deck.push_str("PBAR,5,1,3.-4,4.-8,1.-8,5.-8\n");
            for (i, p) in nodes.iter().enumerate() {
                let _ = writeln!(
                    deck,
                    "GRID,{},,{:.6e},{:.6e},{:.6e}",
                    i + 1,
                    p[0],
                    p[1],
                    p[2]
                );
            }
            // Distinct corners by construction: consecutive offsets from a random start.
            let mut eid = 0;
            for (a, b, c, d) in quads {
                eid += 1;
                let k = a % n;
                let g = |o: usize| (k + o) % n + 1;
                let _ = (b, c, d);
                let _ = writeln!(deck, "CQUAD4,{eid},7,{},{},{},{}", g(0), g(1), g(2), g(3));
            }
            for (a, _, _) in tris {
                eid += 1;
                let k = a % n;
                let g = |o: usize| (k + o) % n + 1;
                let _ = writeln!(deck, "CTRIA3,{eid},7,{},{},{}", g(0), g(1), g(2));
            }
            for (a, _) in bars {
                eid += 1;
                let (ga, gb) = (a % n + 1, (a + 1) % n + 1);
                let _ = writeln!(deck, "CBAR,{eid},5,{ga},{gb},0.3,0.7,1.1");
            }
            // One mass and one spring per grid at most: merged values (sums) need more digits
            // than 16 columns hold, which is the writer's documented precision, not a defect.
            for (j, (a, m)) in masses.into_iter().enumerate() {
                eid += 1;
                let _ = writeln!(deck, "CONM2,{eid},{},,{m:.6e}", (a + j) % n + 1);
            }
            let start = fixed;
            for (j, (_, c, k)) in springs.into_iter().enumerate() {
                eid += 1;
                let _ = writeln!(deck, "CELAS2,{eid},{k:.6e},{},{c}", (start + j) % n + 1);
            }
            let _ = writeln!(deck, "SPC1,1,123,{}", fixed % n + 1);
            deck.push_str("ENDDATA\n");
            deck
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_give_errors_not_panics(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        let limits = DeckLimits { max_line_bytes: 200, ..DeckLimits::default() };
        let _ = parse_reader(&bytes[..], &limits);
        if let Ok(text) = std::str::from_utf8(&bytes) {
            let _ = lex(text);
        }
    }

    #[test]
    fn deck_like_text_gives_errors_not_panics(text in token_deck()) {
        let _ = lex(&text);
        let _ = parse_str(&text);
    }

    #[test]
    fn written_decks_read_back_to_the_same_mesh(deck in random_deck()) {
        // Random geometry may make an element degenerate: such decks are refused, which is
        // fine (proptest fails if too many are); every deck that reads must survive the write-read cycle unchanged (its reals
        // have 7 digits, which the writer's 16 columns hold exactly).
        let first = parse_str(&deck);
        prop_assume!(first.is_ok());
        let first = first.expect("assumed");
        let written = write_bulk_deck(&first.mesh).expect("a mesh read from a deck is writable");
        let second = parse_str(&written).expect("a written deck reads back");
        prop_assert_eq!(&first.mesh, &second.mesh);
    }
}
