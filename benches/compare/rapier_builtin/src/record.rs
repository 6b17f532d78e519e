//! The JSON lines of this crate's cases: the shared helpers with its engine name and version,
//! on one thread.

use compare_common::record::Engine;
pub use compare_common::record::{Record, extend, object};

/// Engine name and the rapier3d version the crate pins (`=0.36.1` in Cargo.toml).
const ENGINE: Engine = Engine {
    name: "rapier_builtin",
    version: "0.36.1",
};

/// Every case runs on this one thread (rapier3d without its `parallel` feature).
const THREADS: usize = 1;

/// The fields every line starts with; `settings` also gets `elements`.
pub fn base(scene: &str, case: &str, settings: Record, elements: usize) -> Record {
    ENGINE.base(scene, case, settings, elements)
}

/// Emits a case that was not run: `stable` and `error` are null and `reason` says why.
pub fn skipped(scene: &str, case: &str, settings: Record, elements: usize, reason: &str) {
    eprintln!("[{scene}] {case}: skipped ({reason})");
    compare_common::record::skipped(base(scene, case, settings, elements), reason, THREADS);
}

/// Writes `record` (with the machine state) as one line on stdout and a summary on stderr.
pub fn emit(record: Record) {
    compare_common::record::emit(record, THREADS);
}
