//! Errors of the recording module.

use std::path::PathBuf;

/// Boxed error from rerun, kept opaque so rerun's types stay inside this module.
pub type BoxError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Everything that can go wrong while recording.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The `.rrd` file could not be created (missing directory, no permission, ...) or the
    /// viewer could not be started or reached.
    #[error("cannot create recording {target}: {source}")]
    Create {
        /// Where the recording was to go ([`super::RecordTarget::describe`]).
        target: String,
        /// What rerun or the file system reported.
        #[source]
        source: BoxError,
    },
    /// Rerun refused to log an entity.
    #[error("cannot log {entity} to recording {target}: {source}")]
    Log {
        /// Where the recording goes.
        target: String,
        /// The entity being logged.
        entity: String,
        /// What rerun reported.
        #[source]
        source: BoxError,
    },
    /// The frame data is inconsistent (length mismatch, index out of range, non-finite time).
    #[error("invalid frame {frame}: {reason}")]
    InvalidFrame {
        /// The frame index.
        frame: u64,
        /// What is wrong with it.
        reason: String,
    },
    /// Flushing or closing the `.rrd` file failed; the file may be incomplete.
    #[error("cannot finish recording {target}: {message}")]
    Finish {
        /// Where the recording goes.
        target: String,
        /// What went wrong.
        message: String,
    },
    /// An OBJ frame file could not be written.
    #[error("cannot write OBJ file {}: {source}", .path.display())]
    Obj {
        /// The OBJ path.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}
