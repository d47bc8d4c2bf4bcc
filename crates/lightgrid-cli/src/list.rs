//! `lightgrid list`: adapters, scenes, pipelines and assignment strategies.

use anyhow::Result;
use lightgrid::gpu::list_adapters;
use lightgrid::pipelines::PIPELINES;
use lightgrid::scene::catalog::SCENES;

pub(crate) fn list() -> Result<()> {
    outln!("adapters (in order of preference):");
    let adapters = list_adapters();
    if adapters.is_empty() {
        outln!("  none found: install mesa-vulkan-drivers for a software Vulkan adapter");
    }
    for a in adapters {
        outln!(
            "  {}: {} [{}, {}] {}",
            a.index,
            a.name,
            a.backend,
            a.device_type,
            a.driver
        );
        // The sample counts need a device; an adapter that will not open one says why.
        match lightgrid::gpu::GpuContext::new(Some(&a.index.to_string())) {
            Ok(ctx) => {
                let counts = |g| {
                    lightgrid::frame::msaa_counts(&ctx, g)
                        .iter()
                        .map(u32::to_string)
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                outln!(
                    "     --msaa: {} (with --gbuffer 32: {})",
                    counts(lightgrid::frame::GBufferFormat::F16),
                    counts(lightgrid::frame::GBufferFormat::F32)
                );
            }
            Err(e) => outln!("     cannot open a device: {e}"),
        }
    }
    outln!("scenes:");
    for s in SCENES {
        outln!("  {:<12} {}", s.name, s.description);
    }
    outln!(
        "  {:<12} a glTF 2.0 file: meshes, materials, textures, cameras, KHR_lights_punctual lights (--add-lights N fills any scene)",
        "FILE.gltf|.glb"
    );
    outln!("pipelines:");
    for p in PIPELINES {
        let msaa = match p.msaa {
            lightgrid::pipelines::Msaa::Supported => "",
            lightgrid::pipelines::Msaa::Refused(_) => " [no MSAA]",
        };
        outln!("  {:<24} {} ({}){msaa}", p.id, p.description, p.paper);
    }
    outln!("light assignment (--assign, for grid pipelines):");
    for a in lightgrid::culling::Assign::all() {
        outln!("  {:<10} {}", a.name(), a.description());
    }
    Ok(())
}
