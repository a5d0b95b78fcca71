//! Integration tests of the Craig-Bampton reduction and its cache (`src/cms`).

mod cache;
mod damping;
mod reduction;
mod transfer;
