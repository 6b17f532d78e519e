//! What the Rust programs of the peer comparison (`benches/compare`) share: the port of
//! `common.py` (scene constants, closed-form references, the damped-oscillation fit, the JSON
//! lines and their timing fields), the command line, and the scenes' measures that do not depend
//! on the engine. Used by `compare_cases` (`rapier_fvm_cases`) and `rapier_builtin_cases`.

pub mod beam;
pub mod cli;
pub mod contact;
pub mod fit;
pub mod record;
pub mod reference;
pub mod stats;
pub mod timing;
