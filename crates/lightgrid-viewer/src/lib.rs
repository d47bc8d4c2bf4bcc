//! The interactive viewer (`lightgrid view`): a winit window with a wgpu surface made from
//! the renderer's own instance (`GpuContext::with_display`), the real-time frame of
//! `lightgrid::Renderer` blitted onto it each redraw, an egui panel to switch pipelines and
//! settings live, and analysis frames on a worker thread for the debug views and counts.
//! - [`app`]: the window, its event handling and the order of one redraw (one file per
//!   part of it);
//! - [`analysis`]: the worker that renders analysis frames so the window never waits;
//! - [`panel`]: the egui panel (it edits a draft of [`controls::Controls`]);
//! - [`live`]: frame times, GPU pass times, fps and the wrong-frame counters;
//! - [`surface`]: the window surface, with recovery from outdated, lost and minimised states;
//! - [`fly`]: the fly camera (WASD + mouse drags), starting at the scene camera;
//! - [`script`]: scripted sessions (`at N ACTION; ...`) for tests and demos;
//! - [`controls`]: the live-editable state and what each change rebuilds;
//! - [`present`]: the display target or a debug view (`lightgrid::debug_view`) drawn onto a
//!   surface-format target, and the screenshot read back from the same drawing.

pub mod analysis;
pub mod app;
pub mod controls;
pub mod fly;
pub mod live;
pub mod panel;
pub mod present;
pub mod script;
pub mod surface;

#[cfg(not(target_arch = "wasm32"))]
pub use app::run;
#[cfg(target_arch = "wasm32")]
pub use app::web;
pub use app::{ViewOptions, ViewReport};
