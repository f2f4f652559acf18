//! `fisheye info`: the adapter, its features and limits, and its trigonometry's precision.

use anyhow::Result;
use fisheye_rt::gpu::GpuContext;

pub(crate) fn info() -> Result<()> {
    let ctx = GpuContext::new()?;
    print!("{}", ctx.report());
    println!("trigonometry, max |error| against f64 (WGSL builtin / fisheye-rt math.wgsl):");
    for t in fisheye_rt::precision::measure_trig(&ctx)? {
        println!(
            "  {:<5} on {:<7} builtin {:9.2e}   ours {:9.2e}",
            t.function, t.domain, t.builtin, t.ours
        );
    }
    Ok(())
}
