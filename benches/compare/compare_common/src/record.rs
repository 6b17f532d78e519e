//! The JSON lines: a case's common fields, the machine it ran on, and their emission.

use serde_json::{Map, Value, json};
use std::io::Write;

/// One line, built up field by field.
pub type Record = Map<String, Value>;

/// The engine a program measures: the `engine` and `engine_version` of its lines.
pub struct Engine {
    /// Engine name on every line.
    pub name: &'static str,
    /// Its version.
    pub version: &'static str,
}

impl Engine {
    /// The fields every line starts with; `settings` also gets `elements`.
    pub fn base(&self, scene: &str, case: &str, mut settings: Record, elements: usize) -> Record {
        settings.insert("elements".into(), json!(elements));
        let mut r = Record::new();
        r.insert("engine".into(), json!(self.name));
        r.insert("engine_version".into(), json!(self.version));
        r.insert("scene".into(), json!(scene));
        r.insert("case".into(), json!(case));
        r.insert("elements".into(), json!(elements));
        r.insert("settings".into(), Value::Object(settings));
        r
    }
}

/// The map inside a `json!` object literal (empty for any other value).
pub fn object(v: Value) -> Record {
    match v {
        Value::Object(map) => map,
        _ => Record::new(),
    }
}

/// Adds every field of the object `fields` to `record`.
pub fn extend(record: &mut Record, fields: Value) {
    if let Value::Object(map) = fields {
        record.extend(map);
    }
}

/// Emits a case that was not run (or was stopped): `stable`, `error` and the times are null
/// and `reason` says why; `threads` as in [`emit`].
pub fn skipped(mut record: Record, reason: &str, threads: usize) {
    extend(
        &mut record,
        json!({
            "skipped": true, "reason": reason, "reference": null, "error": null,
            "stable": null, "ms_per_step": null, "wall_ms_per_step": null,
            "steps_timed": 0, "cpu_s_total": 0.0,
        }),
    );
    emit(record, threads);
}

/// Writes `record` as one line on stdout and a summary on stderr; the line gets the machine
/// state with `threads`, the size of the thread pool the case ran on, unless it has one.
pub fn emit(mut record: Record, threads: usize) {
    record
        .entry("machine")
        .or_insert_with(|| machine_fields(threads));
    let line = serde_json::to_string(&record).expect("a JSON map always serializes");
    let mut out = std::io::stdout().lock();
    writeln!(out, "{line}").expect("stdout is writable");
    out.flush().expect("stdout is writable");
    let get = |k: &str| record.get(k).cloned().unwrap_or(Value::Null);
    let skipped = get("skipped").as_bool().unwrap_or(false);
    eprintln!(
        "[{}] {}: error={} ms/step={} stable={}{}",
        get("scene").as_str().unwrap_or("?"),
        get("case").as_str().unwrap_or("?"),
        get("error")
            .as_f64()
            .map_or("null".into(), |v| format!("{v:+.4}")),
        get("ms_per_step")
            .as_f64()
            .map_or("null".into(), |v| format!("{v:.3}")),
        get("stable"),
        if skipped { " (skipped)" } else { "" },
    );
}

/// CPU count, 1-minute load average, platform and the size of the thread pool the case ran on.
fn machine_fields(threads: usize) -> Value {
    let load1 = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok());
    json!({
        "host_cpus": std::thread::available_parallelism().map(|n| n.get()).ok(),
        "load1": load1,
        "platform": format!("{}-{}", std::env::consts::OS, std::env::consts::ARCH),
        "threads": threads,
    })
}
