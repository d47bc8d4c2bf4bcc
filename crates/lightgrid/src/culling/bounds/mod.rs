//! The cell bounds every strategy reads: per cell the depth range of its samples
//! (`cell_bounds.rs`), a clustered grid's slicing range (`depth_range.rs`), MSAA forward
//! fragments' distances (`fragment_bounds.rs`), and the optional 2.5D depth mask
//! (`depth_mask.rs`) and tight box (`cell_box.rs`). Each kernel has its CPU twin beside it.

pub(crate) mod cell_bounds;
pub(crate) mod cell_box;
pub(crate) mod depth_mask;
pub(crate) mod depth_range;
pub(crate) mod fragment_bounds;
pub(crate) mod samples;

/// Per-tile depth min/max inside a workgroup (the single-kernel tiled deferred pipeline).
pub(crate) const TILE_DEPTH_WGSL: &str = include_str!("tile_depth.wgsl");
/// The 2.5D depth mask's bins (`depth_mask.rs`).
pub(crate) const DEPTH_MASK_WGSL: &str = include_str!("depth_mask.wgsl");
/// The tight cells' record (`cell_box.rs`).
pub(crate) const CELL_BOX_WGSL: &str = include_str!("cell_box.wgsl");
/// Both, in order: what a cell's culling record reads and writes.
pub(crate) const CELL_CULL_WGSL: &[&str] = &[DEPTH_MASK_WGSL, CELL_BOX_WGSL];
