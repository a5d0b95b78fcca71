//! Integration tests of the Craig-Bampton reduction and its cache (`src/cms`).

mod bulk_deck;
mod cache;
mod damping;
mod deck_damping;
mod deck_diagnostics;
mod dmig;
mod reduction;
mod transfer;
