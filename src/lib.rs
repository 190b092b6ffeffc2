//! betr: turn a robot instruction into a behavior tree that people can read, step, verify
//! and trust, and repair it when the world differs from what the planner knew.
//!
//! Data flows one way: `domain` (conditions, skills, scenarios) and `goal` (formulas) are
//! plain data; `bt` runs trees against any leaf executor; `world` simulates; `planner` grows
//! trees by ticking them in a simulated world. Front ends sit on top and are never imported
//! by these modules.
#![forbid(unsafe_code)]

// The lab: evaluations, benchmarks and fuzzing of the product, behind the `lab` feature
// (on by default). Nothing outside these modules imports them.
#[cfg(feature = "lab")]
pub mod bench;
#[cfg(feature = "lab")]
pub mod eval;
#[cfg(feature = "lab")]
pub mod fuzz;

pub mod bounds;
pub mod bt;
pub mod config_file;
pub mod dataset;
pub mod domain;
pub mod excerpt;
pub mod executor;
pub mod goal;
pub mod http_retry;
pub mod http_text;
pub mod interop;
pub mod llm;
pub mod model;
pub mod monitor;
pub mod motion;
pub mod planner;
pub mod reading;
pub mod record;
pub mod robot;
pub mod scenario;
pub mod session;
pub mod store;
pub mod tui;
pub mod verify;
pub mod viz;
pub mod voice;
pub mod world;
