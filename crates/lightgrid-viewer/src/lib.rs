//! The interactive viewer's parts (issue 16, in progress): the window itself (winit, a wgpu
//! surface on `GpuContext::with_display`, an egui panel) is not written yet. What exists and
//! is tested:
//! - [`fly`]: the fly camera (WASD + mouse drags), starting at the scene camera;
//! - [`script`]: scripted sessions (`at N ACTION; ...`) for tests and demos;
//! - [`controls`]: the live-editable state and what each change rebuilds;
//! - [`present`]: the display target or a debug view (`lightgrid::debug_view`) drawn onto a
//!   surface-format target, and the screenshot read back from the same drawing.

pub mod controls;
pub mod fly;
pub mod present;
pub mod script;
