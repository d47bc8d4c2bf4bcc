//! lightgrid: many-lights rendering on wgpu. Forward (the reference), deferred, tiled and
//! clustered shading side by side, sharing one light function and one light-grid contract.
//!
//! Start with [`gpu::GpuContext::new`], build a scene from [`scene::catalog`], and render it
//! with a [`Renderer`] and a pipeline id from [`pipelines::PIPELINES`].

pub mod analysis;
pub mod consts;
pub mod culling;
pub mod debug_view;
pub mod depth;
pub mod error;
pub mod frame;
pub mod gpu;
pub mod gpu_types;
pub mod heatmap;
pub mod image_io;
pub mod memory;
pub mod passes;
pub mod pipelines;
pub mod realtime;
mod renderer;
pub mod scene;
pub mod shader;
pub mod shadows;
pub mod stats;

pub use analysis::FrameOutput;
/// The light grid for any wgpu renderer (`culling/embed/culler.rs`; README, "Embedding").
pub use culling::{
    Assign, CullConfig, CullError, CullInput, CullInputs, CullLight, CullReport, LightCuller,
};
pub use error::{Error, Result};
pub use frame::{CellBox, DepthBounds, DepthMask, SpotCull};
pub use frame::{FinishedFrame, RenderSettings, SubmittedFrame};
pub use renderer::{max_frame_edge, validate_size, Renderer, MAX_FRAMES_IN_FLIGHT};
pub use stats::{Distribution, FrameStats, TimingSource};
