//! Integration tests of the finite elements and the procedural chassis (`src/fe`) against analytic results.

mod beam_cards;
mod beam_shear;
mod chassis;
mod deck_cards;
mod deck_diagnostics;
mod deck_properties;
mod deck_reader;
mod eigen;
mod eigen_slicing;
mod elements;
mod nastran;
mod shell_cards;
mod solids;
