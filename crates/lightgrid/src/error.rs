//! Typed errors of the library. Binaries add context; tests match on variants.

use thiserror::Error;

/// Everything the library can refuse or fail at.
#[derive(Debug, Error)]
pub enum Error {
    /// No adapter at all, or none matching `--adapter`.
    #[error("{0}")]
    NoAdapter(String),
    /// The adapter exists but the device could not be created.
    #[error("could not create a device on adapter '{adapter}': {reason}")]
    Device { adapter: String, reason: String },
    /// A wgpu validation or out-of-memory error caught in an error scope.
    #[error("GPU error during {stage}: {message}")]
    Gpu { stage: String, message: String },
    /// A name that is not in a catalog or registry; `valid` lists the accepted ones.
    #[error("unknown {what} '{name}'; valid: {valid}")]
    Unknown {
        what: &'static str,
        name: String,
        valid: String,
    },
    /// A parameter outside what the renderer or adapter accepts.
    #[error("invalid {what}: {reason}")]
    Invalid { what: &'static str, reason: String },
    /// File I/O, with the path that failed.
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// An image that could not be decoded or encoded.
    #[error("{path}: {reason}")]
    Image { path: String, reason: String },
}

impl Error {
    /// A frame whose per-sample light loop (`loop_length` iterations) would exceed the
    /// adapter's loop budget (`GpuContext::loop_budget`): refused rather than rendered with
    /// lights silently missing.
    pub(crate) fn loop_budget(pipeline: &str, loop_length: u64, budget: u64) -> Self {
        Error::invalid(
            "lights",
            format!(
                "{pipeline} would loop over {loop_length} lights for one sample, but this adapter \
                 (llvmpipe) silently ends a shader's loops after {budget} iterations, which would \
                 drop lights from the image; use fewer lights, a pipeline with smaller light \
                 lists (e.g. clustered_deferred), or a hardware GPU"
            ),
        )
    }

    pub(crate) fn invalid(what: &'static str, reason: impl Into<String>) -> Self {
        Error::Invalid {
            what,
            reason: reason.into(),
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
