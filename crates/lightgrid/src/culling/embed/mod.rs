//! The light grid for other wgpu renderers: [`culler::LightCuller`] (`culler.rs`), the
//! caller's lights turned into the culling kernels' inputs (`cull_lights.wgsl`), and the
//! caller-facing WGSL accessors (`embed.wgsl`).

pub(crate) mod culler;
