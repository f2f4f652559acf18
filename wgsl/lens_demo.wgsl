// Draws what a lens sees of the direction sphere: colour by direction, a 10° latitude and
// longitude grid (y up) and rings every 30° off the optical axis; one invocation per pixel,
// dispatched over the image in WORKGROUP_2D × WORKGROUP_2D tiles. Directions are computed per
// pixel or read from the direction table (`primary_table.wgsl` swapped in), which is what the
// lens benchmark compares.
#import primary

// RGBA8 pixels, row-major.
@group(0) @binding(2) var<storage, read_write> pixels: array<u32>;

const GRID_DEGREES: f32 = 10.0;
const RING_DEGREES: f32 = 30.0;
const LINE_DEGREES: f32 = 0.35;

// Distance in degrees from `angle` to the nearest multiple of `step`.
fn off_grid(angle: f32, step: f32) -> f32 {
    let a = degrees(angle) / step;
    return abs(a - round(a)) * step;
}

fn shade(ray: vec4<f32>) -> vec3<f32> {
    if ray.w == 0.0 {
        return vec3<f32>(0.1);
    }
    let d = normalize(ray.xyz);
    let up = -d.y;
    let elevation = sign(up) * asin_pos(min(abs(up), 1.0));
    let azimuth = atan2_pos(abs(d.x), d.z);
    let off_axis = atan2_pos(length(d.xy), d.z);
    var colour = 0.35 + 0.45 * vec3<f32>(d.x, up, d.z);
    // Meridians converge at the poles: keep their drawn width in degrees of arc.
    let meridian = off_grid(azimuth, GRID_DEGREES) * cos(elevation);
    if off_grid(elevation, GRID_DEGREES) < LINE_DEGREES || meridian < LINE_DEGREES {
        colour = vec3<f32>(0.95);
    }
    if off_grid(off_axis, RING_DEGREES) < LINE_DEGREES {
        colour = vec3<f32>(0.9, 0.2, 0.1);
    }
    return colour;
}

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= lens.width || id.y >= lens.height {
        return;
    }
    let colour = clamp(shade(primary_ray(id.xy)), vec3<f32>(0.0), vec3<f32>(1.0));
    pixels[id.y * lens.width + id.x] = pack4x8unorm(vec4<f32>(colour, 1.0));
}
