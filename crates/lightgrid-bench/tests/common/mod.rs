//! Helpers shared by the GPU tests.
#![allow(dead_code)]

use lightgrid::gpu::GpuContext;
use std::path::PathBuf;

/// A GPU context, or a failing test. A missing adapter is never a pass: install
/// `mesa-vulkan-drivers` for Mesa's software Vulkan adapter (what CI does).
pub fn gpu() -> GpuContext {
    let wanted = std::env::var("LIGHTGRID_ADAPTER").ok();
    match GpuContext::new(wanted.as_deref()) {
        Ok(ctx) => {
            // CI installs lavapipe; a GL fallback there would mean the install step broke.
            if std::env::var("CI").is_ok_and(|v| v == "true") && wanted.is_none() {
                assert_eq!(
                    ctx.info.backend,
                    wgpu::Backend::Vulkan,
                    "under CI the GPU tests must run on Vulkan (lavapipe), got {}",
                    ctx.adapter_label()
                );
            }
            ctx
        }
        Err(e) => panic!(
            "GPU test cannot run: {e}\n(GPU tests fail without an adapter, they never skip; \
             CI installs mesa-vulkan-drivers)"
        ),
    }
}

/// Where failing image tests write the actual image and the diff image.
pub fn output_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output");
    std::fs::create_dir_all(&dir).expect("create target/test-output");
    dir
}

/// Blessed reference images live here; `LIGHTGRID_BLESS=1` rewrites them.
pub fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

pub fn blessing() -> bool {
    std::env::var("LIGHTGRID_BLESS").is_ok_and(|v| v == "1")
}
