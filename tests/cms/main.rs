//! Integration tests of the Craig-Bampton reduction and its cache (`src/cms`).

#[path = "../common/plate_deck.rs"]
mod plate_deck;

mod bulk_deck;
mod cache;
mod damping;
mod deck_damping;
mod deck_diagnostics;
mod dmig;
mod reduction;
mod transfer;
