//! Reading `all.jsonl`: the `run` and `engine_run` lines the driver writes, and one [`Case`] per
//! engine line. A malformed line is an error naming the file and the line, not a panic.

use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

/// Why the input could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A line is not a JSON object.
    #[error("{path}:{line}: not a JSON object: {reason}")]
    Json {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: usize,
        /// What the parser said.
        reason: String,
    },
    /// A case line lacks a required text field.
    #[error("{path}:{line}: a case line needs the text field `{field}`")]
    Field {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: usize,
        /// The missing field.
        field: &'static str,
    },
}

/// One engine's result for one case.
#[derive(Debug, Clone)]
pub struct Case {
    /// `rapier_fvm`, `pybullet`, `mujoco` or `rapier_builtin`.
    pub engine: String,
    /// The scene's name.
    pub scene: String,
    /// The engine's label of the case.
    pub case: String,
    /// The plotted series: the engine and its main knobs, less the resolution.
    pub series: String,
    /// The whole line.
    pub raw: Map<String, Value>,
}

impl Case {
    /// A top-level number, if present and finite.
    pub fn num(&self, key: &str) -> Option<f64> {
        self.raw
            .get(key)
            .and_then(Value::as_f64)
            .filter(|v| v.is_finite())
    }

    /// A number in `settings`, if present and finite.
    pub fn setting(&self, key: &str) -> Option<f64> {
        self.raw
            .get("settings")
            .and_then(|s| s.get(key))
            .and_then(Value::as_f64)
            .filter(|v| v.is_finite())
    }

    /// Whether the case ran and stayed stable.
    pub fn stable(&self) -> bool {
        self.raw.get("stable").and_then(Value::as_bool) == Some(true)
    }

    /// Whether the case is stable and its engine did not flag its result as unconverged
    /// (`cg_cap_converged: false` on rapier's built-in `fem` lines: raising its CG cap moved the
    /// tip by more than 1 % of the reference). Only these are plotted and ranked.
    pub fn trusted(&self) -> bool {
        self.stable() && self.raw.get("cg_cap_converged") != Some(&Value::Bool(false))
    }

    /// The reason a case was skipped, if it was.
    pub fn skipped(&self) -> Option<&str> {
        (self.raw.get("skipped").and_then(Value::as_bool) == Some(true)).then(|| {
            self.raw
                .get("reason")
                .and_then(Value::as_str)
                .unwrap_or("skipped")
        })
    }

    /// Median CPU ms per step.
    pub fn ms(&self) -> Option<f64> {
        self.num("ms_per_step")
    }

    /// Mean CPU ms per step (total CPU over the timed steps).
    pub fn mean_ms(&self) -> Option<f64> {
        let steps = self.num("steps_timed").filter(|&n| n > 0.0)?;
        Some(self.num("cpu_s_total")? * 1e3 / steps)
    }

    /// Threads the case ran on (1 unless it says otherwise).
    pub fn threads(&self) -> f64 {
        self.setting("threads").unwrap_or(1.0)
    }
}

/// The driver's records of the run.
#[derive(Debug, Default)]
pub struct Run {
    /// The `run` line written before the first engine.
    pub start: Option<Map<String, Value>>,
    /// The `run` line written after the last engine.
    pub end: Option<Map<String, Value>>,
    /// One `engine_run` line per engine and scene.
    pub engine_runs: Vec<Map<String, Value>>,
}

/// Reads `path`: the run's records and every case line, in file order.
///
/// # Errors
/// [`ReadError`] when the file cannot be read, a line is not a JSON object, or a case line has
/// no `engine`, `scene` or `case` text.
pub fn read(path: &Path) -> Result<(Run, Vec<Case>), ReadError> {
    let text = std::fs::read_to_string(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let (mut run, mut cases) = (Run::default(), Vec::new());
    for (index, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let json_error = |reason: String| ReadError::Json {
            path: path.to_path_buf(),
            line: index + 1,
            reason,
        };
        let map = match serde_json::from_str::<Value>(line) {
            Ok(Value::Object(map)) => map,
            Ok(_) => return Err(json_error("another JSON value".into())),
            Err(e) => return Err(json_error(e.to_string())),
        };
        match map.get("kind").and_then(Value::as_str) {
            Some("run") if map.get("phase").and_then(Value::as_str) == Some("end") => {
                run.end = Some(map)
            }
            Some("run") => run.start = Some(map),
            Some("engine_run") => run.engine_runs.push(map),
            _ => cases.push(case(map, path, index + 1)?),
        }
    }
    Ok((run, cases))
}

/// A case from its line.
fn case(raw: Map<String, Value>, path: &Path, line: usize) -> Result<Case, ReadError> {
    let text = |field: &'static str| {
        raw.get(field)
            .and_then(Value::as_str)
            .map(str::to_string)
            .ok_or_else(|| ReadError::Field {
                path: path.to_path_buf(),
                line,
                field,
            })
    };
    let (engine, scene, case) = (text("engine")?, text("scene")?, text("case")?);
    let series = series(&engine, &raw);
    Ok(Case {
        engine,
        scene,
        case,
        series,
        raw,
    })
}

/// The series a line is plotted in: this crate's lines name their knobs (`series`); `MuJoCo`'s
/// are split by discretization (`settings.dof`: full, trilinear, quadratic) and rapier's
/// built-in soft bodies by solver (`settings.solver`: constraints, fem); pybullet has one.
fn series(engine: &str, raw: &Map<String, Value>) -> String {
    let setting = |key: &str| {
        raw.get("settings")
            .and_then(|s| s.get(key))
            .and_then(Value::as_str)
    };
    let knob = match engine {
        "mujoco" => setting("dof"),
        "rapier_builtin" => setting("solver"),
        _ => raw.get("series").and_then(Value::as_str),
    };
    match knob {
        Some(knob) => format!("{engine} {knob}"),
        None => engine.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bad_line_is_reported_with_its_number() {
        let path = std::env::temp_dir().join("compare_report_bad_line.jsonl");
        std::fs::write(
            &path,
            "{\"kind\": \"run\"}\n{\"engine\": \"x\", \"scene\": \"s\", \"case\": \"c\"}\nnot json\n",
        )
        .unwrap();
        let error = read(&path).unwrap_err();
        assert!(matches!(error, ReadError::Json { line: 3, .. }), "{error}");
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn peers_are_split_by_their_main_knob() {
        let line =
            r#"{"engine": "mujoco", "scene": "s", "case": "c", "settings": {"dof": "quadratic"}}"#;
        let Value::Object(raw) = serde_json::from_str(line).unwrap() else {
            panic!("an object")
        };
        assert_eq!(series("mujoco", &raw), "mujoco quadratic");
        assert_eq!(series("pybullet", &raw), "pybullet");
    }
}
