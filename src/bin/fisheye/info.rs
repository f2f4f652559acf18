//! `fisheye info`: the adapter, its features and limits, and its trigonometry's precision; with
//! `--scene`, what a scene takes on the device.

use anyhow::Result;
use fisheye_rt::gpu::GpuContext;
use fisheye_rt::trace::{GpuScene, RenderOptions};

use crate::args::{Quality, load_scene_with};

#[derive(clap::Args)]
pub(crate) struct InfoArgs {
    /// Also build and upload this scene (as `render` takes it) and report its triangles, BVH,
    /// bytes on the device per stored triangle and the storage bindings it is split across.
    #[arg(long)]
    pub(crate) scene: Option<String>,
    /// Which scene of a glTF file (from 0); its default scene if not given.
    #[arg(long)]
    pub(crate) gltf_scene: Option<usize>,
    /// BVH build preset for --scene.
    #[arg(long, value_enum, default_value = "fast")]
    pub(crate) bvh: Quality,
}

pub(crate) fn info(args: &InfoArgs) -> Result<()> {
    let ctx = GpuContext::new()?;
    print!("{}", ctx.report());
    println!("trigonometry, max |error| against f64 (WGSL builtin / fisheye-rt math.wgsl):");
    for t in fisheye_rt::precision::measure_trig(&ctx)? {
        println!(
            "  {:<5} on {:<7} builtin {:9.2e}   ours {:9.2e}",
            t.function, t.domain, t.builtin, t.ours
        );
    }
    if let Some(spec) = &args.scene {
        let scene = load_scene_with(spec, args.gltf_scene)?;
        let options = RenderOptions {
            bvh: args.bvh.into(),
            ..RenderOptions::default()
        };
        let gpu = GpuScene::new(&ctx, &scene, &options)?;
        print!(
            "{}",
            crate::render::scene_report(spec, &scene, &gpu, options.bvh)
        );
    }
    Ok(())
}
