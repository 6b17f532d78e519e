//! The JSON lines of this crate's cases: the shared helpers with its engine name, the series of
//! a case, and the size of the pool it ran on.

use compare_common::record::Engine;
pub use compare_common::record::{Record, extend, object};
use serde_json::json;

/// Engine name and the workspace's version (the library and the runner share it).
const ENGINE: Engine = Engine {
    name: "rapier_fvm",
    version: env!("CARGO_PKG_VERSION"),
};

/// The fields every line starts with. `settings` also gets `elements`; `series` names the
/// crate's knobs the case was run with, less its resolution (one series per plotted line).
pub fn base(scene: &str, case: &str, series: &str, settings: Record, elements: usize) -> Record {
    let mut r = ENGINE.base(scene, case, settings, elements);
    r.insert("series".into(), json!(series));
    r
}

/// Emits a case that was not run (or was stopped): `stable`, `error` and the times are null
/// and `reason` says why.
pub fn skipped(record: Record, reason: &str) {
    compare_common::record::skipped(record, reason, rayon::current_num_threads());
}

/// Writes `record` (with the machine state and the current pool's size) as one line on stdout
/// and a summary on stderr.
pub fn emit(record: Record) {
    compare_common::record::emit(record, rayon::current_num_threads());
}
