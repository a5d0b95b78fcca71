//! Integration tests of the BDF integrator (`src/ode`): accuracy against exact solutions, API contracts, snapshots.

mod api;
mod block_low_rank;
mod chain;
mod jacobian_mass;
mod magnitude_cap;
mod snapshot;
mod stop_time;
mod tolerance;
