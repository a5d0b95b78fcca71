//! Prints the supported-card table of the bulk deck reader as the user guide shows it (Markdown):
//! every card the reader accepts with what it becomes, the fields read, what is refused and which
//! card the writer writes for it, the
//! ignored `PARAM`s, and the cards often met in production decks that it refuses, with what to
//! use instead. `docs/generate.py` puts the output into docs/src/cae/bulk-deck.md.
//!
//! `cargo run --release --example supported_cards`

use engine_mount_chassis::nastran::card_table::{CARD_TABLE, IGNORED_PARAMS, REFUSED_CARDS};

fn code_list(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn main() {
    println!("| card | read as | fields read | refused | written back as |");
    println!("|---|---|---|---|---|");
    for row in CARD_TABLE {
        let dash = |s: &str| {
            if s.is_empty() {
                "–".to_owned()
            } else {
                s.to_owned()
            }
        };
        let names: Vec<&str> = row.cards.iter().map(|card| card.name).collect();
        println!(
            "| {} | {} | {} | {} | {} |",
            code_list(&names),
            row.read_as,
            dash(row.fields),
            dash(row.refused),
            dash(&code_list(row.written))
        );
    }
    println!();
    println!(
        "Ignored `PARAM`s (output and bookkeeping): {}.",
        code_list(&IGNORED_PARAMS)
    );
    println!();
    println!(
        "Cards often met in production decks that the reader refuses, and what to use instead:"
    );
    println!();
    println!("| card | use instead |");
    println!("|---|---|");
    for (cards, instead) in REFUSED_CARDS {
        let names: Vec<&str> = cards.split(", ").collect();
        println!("| {} | {instead} |", code_list(&names));
    }
}
