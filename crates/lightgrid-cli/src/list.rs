//! `lightgrid list`: adapters, scenes, pipelines and assignment strategies.

use anyhow::Result;
use lightgrid::gpu::list_adapters;
use lightgrid::pipelines::PIPELINES;
use lightgrid::scene::catalog::SCENES;

pub(crate) fn list() -> Result<()> {
    println!("adapters (in order of preference):");
    let adapters = list_adapters();
    if adapters.is_empty() {
        println!("  none found: install mesa-vulkan-drivers for a software Vulkan adapter");
    }
    for a in adapters {
        println!(
            "  {}: {} [{}, {}] {}",
            a.index, a.name, a.backend, a.device_type, a.driver
        );
    }
    println!("scenes:");
    for s in SCENES {
        println!("  {:<12} {}", s.name, s.description);
    }
    println!("pipelines:");
    for p in PIPELINES {
        println!("  {:<24} {} ({})", p.id, p.description, p.paper);
    }
    println!("light assignment (--assign, for grid pipelines):");
    for a in lightgrid::culling::Assign::ALL {
        println!("  {:<10} {}", a.name(), a.description());
    }
    Ok(())
}
