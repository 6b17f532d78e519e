//! The one error type of the writers: which file could not be written, and why.

use std::path::PathBuf;

/// A file that could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// Creating or writing `path` failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The VTK writer rejected the data for `path`.
    #[error("cannot write {path}: {message}")]
    Vtk {
        /// The `.vtu` file.
        path: PathBuf,
        /// vtkio's error.
        message: String,
    },
    /// Drawing or encoding the picture `path` failed.
    #[error("cannot draw {path}: {message}")]
    Picture {
        /// The PNG file.
        path: PathBuf,
        /// plotters' error.
        message: String,
    },
}

impl OutputError {
    /// An [`OutputError::Io`] for `path`.
    pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| Self::Io { path, source }
    }

    /// An [`OutputError::Picture`] for `path` from any displayable drawing error.
    pub(crate) fn picture<E: std::fmt::Display>(
        path: impl Into<PathBuf>,
    ) -> impl FnOnce(E) -> Self {
        let path = path.into();
        move |error| Self::Picture {
            path,
            message: error.to_string(),
        }
    }
}
