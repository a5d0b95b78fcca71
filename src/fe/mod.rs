//! Finite elements, sparse assembly and the procedural chassis body.
