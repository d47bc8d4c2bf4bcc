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
    Device {
        /// The adapter's name as the driver reports it.
        adapter: String,
        /// wgpu's message for the failed device request.
        reason: String,
    },
    /// A wgpu validation or out-of-memory error caught in an error scope.
    #[error("GPU error during {stage}: {message}")]
    Gpu {
        /// What the library was doing when it failed (e.g. "submitting a frame part").
        stage: String,
        /// What went wrong: wgpu's error message, or the library's own where it checks.
        message: String,
    },
    /// A name that is not in a catalog or registry; `valid` lists the accepted ones.
    #[error("unknown {what} '{name}'; valid: {valid}")]
    Unknown {
        /// The kind of name looked up (`"scene"`, `"pipeline"`, ...).
        what: &'static str,
        /// The name as given.
        name: String,
        /// The accepted names, comma-separated.
        valid: String,
    },
    /// A parameter outside what the renderer or adapter accepts.
    #[error("invalid {what}: {reason}")]
    Invalid {
        /// The parameter or input that was refused.
        what: &'static str,
        /// Why it was refused.
        reason: String,
    },
    /// File I/O, with the path that failed. The cause is part of the message and not a
    /// `source()`, so a reporter that prints the chain says it once.
    #[error("{path}: {cause}")]
    Io {
        /// The path the operation failed on, as displayed to the user.
        path: String,
        /// The underlying I/O error.
        cause: std::io::Error,
    },
    /// Shader loops of a frame ended before their bound (llvmpipe ends an invocation's loops
    /// after 65,536 iterations without an error): the image is missing work, so it is refused.
    #[error(
        "{pipeline}: {count} shader loops ended before their bound (this adapter silently cuts \
         long loops short), so the image would be missing light; use fewer lights, a larger \
         --tile or more --slices, a pipeline with shorter light lists (e.g. clustered_deferred), \
         or a hardware GPU"
    )]
    TruncatedLoops {
        /// Id of the pipeline that rendered the frame.
        pipeline: String,
        /// Shader loops of the frame that ended before their bound.
        count: u32,
    },
    /// The light lists of a frame did not fit their buffers even after growing them.
    #[error("{pipeline}: {reason}")]
    Overflow {
        /// Id of the pipeline whose light lists overflowed.
        pipeline: String,
        /// What did not fit.
        reason: String,
    },
    /// An image that could not be decoded or encoded.
    #[error("{path}: {reason}")]
    Image {
        /// The image file (or name) that failed, as displayed to the user.
        path: String,
        /// The decoder's or encoder's message, or why the file was refused.
        reason: String,
    },
    /// A glTF file that cannot be loaded: the file and what is wrong with it.
    #[error("{path}: {reason}")]
    Gltf {
        /// The glTF file as the user named it.
        path: String,
        /// What is wrong with it.
        reason: String,
    },
}

impl Error {
    pub(crate) fn invalid(what: &'static str, reason: impl Into<String>) -> Self {
        Error::Invalid {
            what,
            reason: reason.into(),
        }
    }
}

/// The library's result type, with [`Error`](enum@Error) as the default error.
pub type Result<T, E = Error> = std::result::Result<T, E>;
