//! Light assignment: the light grid contract (tiled-shading §6.2), its CPU builder, the
//! brute-force oracle that proves the builder never misses a light, and per-tile depth bounds
//! (GPU kernel and its CPU twin).

mod assign_cpu;
mod depth_bounds;
mod gather;
mod grid;
mod oracle;
mod view;

pub use assign_cpu::{assign_cpu, cluster_occupancy, project_sphere, DepthRange, PixelRect};
pub use depth_bounds::{depth_bounds_cpu, to_view_bounds, DepthBoundsPass};
pub(crate) use depth_bounds::{shader as depth_bounds_shader, TILE_DEPTH_WGSL};

/// `tile_frustum` / `light_in_tile` (needs the scene bindings).
pub(crate) const TILE_FRUSTUM_WGSL: &str = include_str!("tile_frustum.wgsl");
pub(crate) use gather::shader as gather_shader;
pub use gather::{assign_gather_cpu, gather_margins, GatherPass};
pub use grid::{GridBuffers, GridDims, LightGrid};
pub use oracle::{ideal_lighting_computations, oracle_tile_lights};
pub use view::{ViewLight, ViewSetup};
