//! Integration tests of the body rooms against analytic results and independent solutions:
//! general finite elements (`src/fe`: elements, solids, beams with shear), the procedural chassis
//! (`src/chassis`), the Nastran deck (`src/nastran`: reader, cards, properties, diagnostics) and
//! the eigensolvers (`src/eigen`). One binary: each links the whole crate.

// src/fe
mod beam_shear;
mod elements;
mod solids;
// src/chassis
mod chassis;
// src/nastran
mod beam_cards;
mod deck_cards;
mod deck_diagnostics;
mod deck_properties;
mod deck_reader;
mod nastran;
mod shell_cards;
// src/eigen
mod eigen;
mod eigen_slicing;
