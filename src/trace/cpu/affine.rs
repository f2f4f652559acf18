//! The f32 maps of instances, as the GPU applies them.

use glam::{DMat3, DVec3};

/// An affine map read from the rows the GPU gets.
#[derive(Clone, Copy)]
pub(super) struct Affine {
    pub(super) m: DMat3,
    pub(super) t: DVec3,
}

impl Affine {
    pub(super) fn from_rows(rows: [[f32; 4]; 3]) -> Self {
        let row = |r: [f32; 4]| DVec3::new(r[0].into(), r[1].into(), r[2].into());
        Self {
            m: DMat3::from_cols(row(rows[0]), row(rows[1]), row(rows[2])).transpose(),
            t: DVec3::new(rows[0][3].into(), rows[1][3].into(), rows[2][3].into()),
        }
    }
}
