//! lightgrid: many-lights rendering on wgpu. Forward (the reference), deferred, tiled and
//! clustered shading side by side, sharing one light function and one light-grid contract.
//!
//! Start with [`gpu::GpuContext::new`], build a scene from [`scene::catalog`], and render it
//! with a [`Renderer`] and a pipeline id from [`pipelines::PIPELINES`].

#![warn(missing_docs)]

pub mod analysis;
pub mod consts;
pub mod culling;
pub mod debug_view;
pub mod depth;
pub mod error;
pub mod frame;
pub mod gpu;
mod gpu_types;
pub mod heatmap;
pub mod image_io;
pub mod memory;
pub mod passes;
pub mod pipelines;
pub mod realtime;
mod renderer;
pub mod scene;
// Shader composition: public for lightgrid's own tests (the `testing` feature); a renderer
// composes its own WGSL with `compose` into a `ComposedShader`.
#[cfg(feature = "testing")]
pub mod shader;
#[cfg(not(feature = "testing"))]
mod shader;
pub mod shadows;
pub mod stats;

pub use analysis::FrameOutput;
/// The light grid for any wgpu renderer (`culling/embed/culler.rs`; README, "Embedding").
pub use culling::{
    Assign, CullConfig, CullError, CullExtras, CullInput, CullInputs, CullLight, CullReport,
    LightCuller, LightLayout,
};
pub use error::{Error, Result};
pub use frame::{CellBox, DepthBounds, DepthMask, SpotCull};
pub use frame::{FinishedFrame, RenderSettings, SubmittedFrame};
pub use renderer::{max_frame_edge, validate_size, Renderer, MAX_FRAMES_IN_FLIGHT};
pub use shader::{compose, ComposedShader};
pub use stats::{Distribution, FrameStats, TimingSource};

/// lightgrid's own tests' view of its internals (the `testing` feature, which only the
/// crate's tests turn on; not an API): the CPU twin of every culling stage, the brute-force
/// oracle, the strategies' registry and the GPU-side layouts (`gpu_types`).
#[cfg(feature = "testing")]
pub mod testing {
    pub use crate::culling::testing::*;
    /// The `#[repr(C)]` structs the shaders read, field for field.
    pub mod gpu_types {
        pub use crate::gpu_types::*;
    }
}
