//! Integration tests of the finite elements and the procedural chassis (`src/fe`) against analytic results.

mod chassis;
mod eigen;
mod elements;
mod nastran;
