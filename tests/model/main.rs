//! Integration tests of the coupled engine–mount–body model (`src/model`): statics, modes, orders, Jacobians, time domain.

mod engine_imperfections;
mod engine_inputs_outputs;
mod engine_jacobian;
mod engine_modes;
mod engine_reactions;
mod engine_statics;
mod engine_time_domain;
mod hybrid_coupling;
mod hybrid_paper;
mod inline_four;
mod scene_effects;
mod torque_path;
mod wrench_orders;
