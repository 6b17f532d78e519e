//! The advisor's folder: `trials/` (one run's output folder per alternative), the recommended
//! scene and `advice.json`.

use super::candidates::edit_text;
use super::{Advice, AdviseError};
use crate::scene::Scene;
use crate::scene::edit::edited;
use std::path::{Path, PathBuf};
use toml_edit::Value;

/// The file `advise` leaves in its `trials/` folder, so that a later advice into the same
/// output folder knows the folder is its own to empty.
const MARK: &str = ".written-by-rapier-fvm-advise";

/// Makes the output folder `out` for advising on the scene `path`: an earlier advice's
/// `trials/`, `advice.json` and `recommended.toml` are removed (a `trials/` folder without
/// the mark `advise` leaves is not: the advice is refused); returns the trials' folder, marked.
///
/// # Errors
/// [`AdviseError::Overwrite`] if `out/recommended.toml` is the scene file itself or `out/trials`
/// is a folder `advise` did not write, and [`AdviseError::Write`] if a folder cannot be made,
/// emptied or marked.
pub fn prepare_folder(path: &Path, out: &Path) -> Result<PathBuf, AdviseError> {
    let written = out.join("recommended.toml");
    if let (Ok(a), Ok(b)) = (std::fs::canonicalize(path), std::fs::canonicalize(&written))
        && a == b
    {
        return Err(AdviseError::Overwrite(format!(
            "{}: the output folder's recommended.toml would overwrite the scene",
            path.display()
        )));
    }
    let trials = out.join("trials");
    if trials.exists() {
        if !trials.join(MARK).is_file() {
            return Err(AdviseError::Overwrite(format!(
                "{}: a folder advise did not write; advise would empty it",
                trials.display()
            )));
        }
        std::fs::remove_dir_all(&trials).map_err(|e| AdviseError::Write(trials.clone(), e))?;
        for file in ["advice.json", "recommended.toml"] {
            let file = out.join(file);
            if file.is_file() {
                std::fs::remove_file(&file).map_err(|e| AdviseError::Write(file.clone(), e))?;
            }
        }
    }
    std::fs::create_dir_all(&trials).map_err(|e| AdviseError::Write(trials.clone(), e))?;
    let mark = trials.join(MARK);
    std::fs::write(&mark, "").map_err(|e| AdviseError::Write(mark, e))?;
    Ok(trials)
}

/// The folder of the `k`-th alternative, labelled `label`.
pub fn folder_name(k: usize, label: &str) -> String {
    let slug: String = (label.chars())
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    format!("{:02}_{slug}", k + 1)
}

/// Writes the scene's text with `edits` into `file`: the files it names (meshes of soft bodies,
/// triangle meshes of rigid ones; relative to the scene's folder) by absolute paths, and its
/// name kept (it was the file's stem when not given), under a comment naming the changes.
///
/// # Errors
/// [`AdviseError::Write`] if a path cannot be made absolute or the file cannot be written.
pub fn write_recommended(
    scene: &Scene,
    (path, text): (&Path, &str),
    edits: &[(String, Value)],
    file: &Path,
) -> Result<(), AdviseError> {
    let folder = path.parent().unwrap_or(Path::new("."));
    let absolute = |name: &str| -> Result<Value, AdviseError> {
        let joined = folder.join(name);
        // Canonical where the file exists (no `..` left), else absolute.
        let absolute = match std::fs::canonicalize(&joined) {
            Ok(canonical) => canonical,
            Err(_) => std::path::absolute(&joined).map_err(|e| AdviseError::Write(joined, e))?,
        };
        Ok(Value::from(absolute.display().to_string()))
    };
    let mut all = edits.to_vec();
    for (i, body) in scene.soft_body.iter().enumerate() {
        for (key, mesh) in [
            ("mesh", Some(&body.mesh)),
            ("embedded", body.embedded.as_ref()),
        ] {
            if let Some(name) = mesh.and_then(|m| m.file.as_deref()) {
                all.push((format!("soft_body[{i}].{key}.file"), absolute(name)?));
            }
        }
    }
    for (i, body) in scene.rigid_body.iter().enumerate() {
        if let crate::scene::rigid_body::ShapeSpec::Trimesh { file, .. } = &body.shape {
            all.push((
                format!("rigid_body[{i}].shape.trimesh.file"),
                absolute(file)?,
            ));
        }
    }
    if scene.name.is_none() {
        all.push(("name".to_owned(), Value::from(scene.display_name())));
    }
    let body = edited(text, &all).map_err(|e| AdviseError::Edit(e.to_string()))?;
    let changes = if edits.is_empty() {
        "no change was cheaper within the target".to_owned()
    } else {
        edits.iter().map(edit_text).collect::<Vec<_>>().join(", ")
    };
    // One line, whatever the path holds.
    let source = path.display().to_string().replace(['\n', '\r'], " ");
    let header = format!("# Written by `rapier-fvm advise` from {source}: {changes}\n");
    std::fs::write(file, header + &body).map_err(|e| AdviseError::Write(file.to_path_buf(), e))
}

/// Writes `advice` as JSON into `file`.
///
/// # Errors
/// [`AdviseError::Write`] if the file cannot be written.
pub fn write_json(advice: &Advice, file: &Path) -> Result<(), AdviseError> {
    let json = serde_json::to_string_pretty(advice)
        .map_err(|e| AdviseError::Write(file.to_path_buf(), std::io::Error::other(e)))?;
    std::fs::write(file, json).map_err(|e| AdviseError::Write(file.to_path_buf(), e))
}
