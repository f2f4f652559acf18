//! Optical flow's files beyond NPY and OpenEXR: Middlebury's `.flo` (Baker et al., "A
//! Database and Evaluation Methodology for Optical Flow", IJCV 2011: the tag 202021.25 as a
//! float, width and height as 32-bit integers, then u and v interleaved by rows, all little
//! endian; a component above 10⁹ is unknown), which `cv2.readOpticalFlow` reads; and KITTI's
//! 16-bit PNG (Geiger et al. 2012, its devkit's `flow_read`: red and green u·64 + 2¹⁵, blue 1
//! where the flow is valid).

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result};
use crate::lens::ImageSize;
use crate::trace::{save_png, write_atomically};

/// What Middlebury's files write for an unknown component (above their 10⁹ threshold).
const UNKNOWN: f32 = 1e10;

/// Writes `flow` (row-major, NaN where unknown) as a Middlebury `.flo` file.
pub fn write_flo(path: &Path, size: ImageSize, flow: &[[f32; 2]]) -> Result<()> {
    let mut bytes = Vec::with_capacity(12 + 8 * flow.len());
    bytes.extend(202021.25f32.to_le_bytes());
    bytes.extend((size.width as i32).to_le_bytes());
    bytes.extend((size.height as i32).to_le_bytes());
    for v in flow.iter().flatten() {
        bytes.extend(if v.is_finite() { *v } else { UNKNOWN }.to_le_bytes());
    }
    write_atomically(path, |temporary| {
        std::fs::File::create(temporary)
            .and_then(|mut f| f.write_all(&bytes))
            .map_err(|reason| Error::Io {
                path: path.to_path_buf(),
                reason,
            })
    })
}

/// Writes `flow` and its validity as KITTI's 16-bit PNG: a component u is stored as
/// u·64 + 2¹⁵ (to 1/64 px, clamped to the 16 bits: ±512 px), and blue is 1 where `valid`;
/// unknown flow is all zero.
pub fn write_kitti(path: &Path, size: ImageSize, flow: &[[f32; 2]], valid: &[u8]) -> Result<()> {
    let store = |u: f32| (f64::from(u) * 64.0 + 32768.0).round().clamp(0.0, 65535.0) as u16;
    let pixels: Vec<u16> = flow
        .iter()
        .zip(valid)
        .flat_map(|(v, &ok)| match v[0].is_finite() && v[1].is_finite() {
            true => [store(v[0]), store(v[1]), u16::from(ok)],
            false => [0; 3],
        })
        .collect();
    let image = image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(size.width, size.height, pixels)
        .expect("three channels a pixel");
    save_png(&image, path)
}
