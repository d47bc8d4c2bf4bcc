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
    /// File I/O, with the path that failed. The cause is part of the message and not a
    /// `source()`, so a reporter that prints the chain says it once.
    #[error("{path}: {cause}")]
    Io { path: String, cause: std::io::Error },
    /// Shader loops of a frame ended before their bound (llvmpipe ends an invocation's loops
    /// after 65,536 iterations without an error): the image is missing work, so it is refused.
    #[error(
        "{pipeline}: {count} shader loops ended before their bound (this adapter silently cuts \
         long loops short), so the image would be missing light; use fewer lights, a larger \
         --tile or more --slices, a pipeline with shorter light lists (e.g. clustered_deferred), \
         or a hardware GPU"
    )]
    TruncatedLoops { pipeline: String, count: u32 },
    /// The light lists of a frame did not fit their buffers even after growing them.
    #[error("{pipeline}: {reason}")]
    Overflow { pipeline: String, reason: String },
    /// An image that could not be decoded or encoded.
    #[error("{path}: {reason}")]
    Image { path: String, reason: String },
    /// A glTF file that cannot be loaded: the file and what is wrong with it.
    #[error("{path}: {reason}")]
    Gltf { path: String, reason: String },
}

impl Error {
    pub(crate) fn invalid(what: &'static str, reason: impl Into<String>) -> Self {
        Error::Invalid {
            what,
            reason: reason.into(),
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
