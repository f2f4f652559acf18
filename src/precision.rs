//! Measures, on the adapter in use, the WGSL trigonometric builtins and this project's
//! replacements (`wgsl/math.wgsl`) against f64. WGSL promises little for the builtins (sin and
//! cos to 2^-11 absolute), so the lens code uses the replacements, whose bound holds on any
//! driver; `fisheye info` prints both.

use crate::error::Result;
use crate::gpu::GpuContext;
use crate::shader::compute_pipeline;

/// The largest absolute error of one function over its probed domain.
#[derive(Clone, Debug)]
pub struct TrigError {
    /// The function, e.g. `sin`.
    pub function: &'static str,
    /// The probed arguments, e.g. `[0, 8]`.
    pub domain: &'static str,
    /// Max |error| of the WGSL builtin.
    pub builtin: f64,
    /// Max |error| of this project's replacement.
    pub ours: f64,
}

/// Arguments probed: a dense even grid on [0, 8] (past 2π) plus the reduction boundaries.
fn arguments() -> Vec<f32> {
    let n = 1 << 16;
    let mut args: Vec<f32> = (0..=n).map(|i| 8.0 * i as f32 / n as f32).collect();
    for k in 1..=5 {
        let boundary = k as f32 * std::f32::consts::FRAC_PI_4;
        args.extend([boundary, boundary.next_up(), boundary.next_down()]);
    }
    args.extend([0.4142135, 0.41421357, 2.4142135, 2.4142137, 4.0]);
    args
}

/// Probes sin and cos on [0, 8], atan on [0, 8] and asin on [0, 1].
pub fn measure_trig(ctx: &GpuContext) -> Result<Vec<TrigError>> {
    let args = arguments();
    let values = ctx.checked("probing trigonometry", || {
        let device = &ctx.device;
        let pipeline = compute_pipeline(device, "trig_probe", "main", &[], &[]);
        let input = crate::gpu::buffer_init(
            device,
            "fisheye.trig_probe.args",
            bytemuck::cast_slice(&args),
            wgpu::BufferUsages::STORAGE,
        );
        let values = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fisheye.trig_probe.values"),
            size: 32 * args.len() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind_group = crate::gpu::bind_buffers(
            device,
            "fisheye.trig_probe",
            &pipeline.get_bind_group_layout(0),
            &[&input, &values],
        );
        crate::gpu::submit_over_elements(ctx, &pipeline, &bind_group, args.len());
        values
    })?;
    let values: Vec<[f32; 8]> = ctx.read_buffer(&values)?;
    type Reference = fn(f64) -> f64;
    let functions: [(&str, &str, Reference); 4] = [
        ("sin", "[0, 8]", f64::sin),
        ("cos", "[0, 8]", f64::cos),
        ("atan", "[0, 8]", f64::atan),
        ("asin", "[0, 1]", |x| (x / 8.0).asin()),
    ];
    Ok(functions
        .iter()
        .enumerate()
        .map(|(k, &(function, domain, reference))| {
            let mut builtin = 0.0f64;
            let mut ours = 0.0f64;
            for (x, v) in args.iter().zip(&values) {
                let exact = reference(f64::from(*x));
                builtin = builtin.max((f64::from(v[k]) - exact).abs());
                ours = ours.max((f64::from(v[k + 4]) - exact).abs());
            }
            TrigError {
                function,
                domain,
                builtin,
                ours,
            }
        })
        .collect())
}
