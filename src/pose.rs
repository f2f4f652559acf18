//! Rigid transforms as trajectories and rig calibrations write them, checked on the way in.
//!
//! A transform `T_a_b` (a [`DAffine3`] with an orthonormal, right-handed rotation) maps
//! coordinates in frame `b` to frame `a`: `p_a = T_a_b · p_b`. Camera frames are OpenCV's
//! (x right, y down, z forward), as Kalibr, Basalt, KITTI and this project's lens models use.

use glam::{DAffine3, DMat3, DQuat, DVec3};

/// How far a quaternion's norm may be from 1 before it is refused rather than normalised:
/// files print 4 to 9 decimals, so a unit quaternion written to 4 decimals is within 2·10⁻⁴.
const QUATERNION_NORM_TOLERANCE: f64 = 1e-2;

/// How far `RᵀR` may be from the identity, entry by entry, before a rotation matrix is refused:
/// KITTI prints 6 significant digits (errors near 10⁻⁶).
pub const ORTHONORMAL_TOLERANCE: f64 = 1e-3;

/// The rotation of a quaternion given as `(x, y, z, w)`, normalised; refused when it is not
/// finite or not within 1% of unit length.
pub fn rotation_from_quaternion(x: f64, y: f64, z: f64, w: f64) -> Result<DQuat, String> {
    let q = DQuat::from_xyzw(x, y, z, w);
    let norm = q.length();
    if !norm.is_finite() || (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(format!(
            "the quaternion (x, y, z, w) = ({x}, {y}, {z}, {w}) has length {norm}, not 1"
        ));
    }
    Ok(q / norm)
}

/// The rotation of a 3×3 matrix given by rows, made exactly orthonormal; refused when it is not
/// a rotation to [`ORTHONORMAL_TOLERANCE`] (a reflection, a scale, a shear).
pub fn rotation_from_rows(rows: [[f64; 3]; 3]) -> Result<DQuat, String> {
    let m = DMat3::from_cols_array_2d(&rows).transpose();
    let gram = m.transpose() * m;
    let off = (gram - DMat3::IDENTITY)
        .to_cols_array()
        .into_iter()
        .fold(0.0f64, |a, e| a.max(e.abs()));
    if !off.is_finite() || off > ORTHONORMAL_TOLERANCE || m.determinant() <= 0.0 {
        return Err(format!(
            "the rotation {rows:?} is not a rotation matrix (RᵀR differs from the identity by \
             {off:.2e}, determinant {:.6})",
            m.determinant()
        ));
    }
    Ok(DQuat::from_mat3(&m).normalize())
}

/// A rigid transform from its rotation and translation.
pub fn rigid(rotation: DQuat, translation: DVec3) -> DAffine3 {
    DAffine3::from_rotation_translation(rotation, translation)
}

/// The rigid transform a share `s` (0 to 1) of the way from `a` to `b`: the translation
/// interpolated linearly and the rotation by spherical linear interpolation on the shortest
/// arc (Shoemake, "Animating Rotation with Quaternion Curves", SIGGRAPH 1985: constant angular
/// velocity about one axis). `wgsl/frame.wgsl` turns a moving camera the same way in f32.
pub fn interpolate(a: &DAffine3, b: &DAffine3, s: f64) -> DAffine3 {
    let rotation = |t: &DAffine3| DQuat::from_mat3(&t.matrix3).normalize();
    let (ra, rb) = (rotation(a), rotation(b));
    // q and -q are one rotation: take the nearer, so the arc is the shortest.
    let rb = if ra.dot(rb) < 0.0 { -rb } else { rb };
    let translation = a.translation.lerp(b.translation, s);
    DAffine3::from_rotation_translation(ra.slerp(rb, s).normalize(), translation)
}

/// A rigid transform from the rows of a 3×4 `[R | t]` or 4×4 matrix (the last row then
/// `0 0 0 1`).
pub fn rigid_from_rows(rows: &[Vec<f64>]) -> Result<DAffine3, String> {
    let shape = rows.len() == 3 || rows.len() == 4;
    if !shape || rows.iter().take(3).any(|r| r.len() != 4) {
        return Err("a transform is a 3×4 or 4×4 matrix given by rows".into());
    }
    if let Some(last) = rows.get(3)
        && last[..] != [0.0, 0.0, 0.0, 1.0]
    {
        return Err(format!(
            "a rigid transform's last row is [0, 0, 0, 1], not {last:?}"
        ));
    }
    let r = |i: usize| [rows[i][0], rows[i][1], rows[i][2]];
    let rotation = rotation_from_rows([r(0), r(1), r(2)])?;
    let translation = DVec3::new(rows[0][3], rows[1][3], rows[2][3]);
    if !translation.is_finite() {
        return Err(format!("the translation {translation} is not finite"));
    }
    Ok(rigid(rotation, translation))
}

/// A transform written on a command line: `tx,ty,tz,qx,qy,qz,qw` (metres, a unit quaternion),
/// `identity`, or `z-up`: a world whose z axis points up, as most robotics datasets' do, turned
/// into a scene whose y axis does (x stays, z becomes y, y becomes -z).
pub fn parse_transform(text: &str) -> Result<DAffine3, String> {
    match text.trim() {
        "identity" => return Ok(DAffine3::IDENTITY),
        "z-up" => return Ok(DAffine3::from_rotation_x(-std::f64::consts::FRAC_PI_2)),
        _ => {}
    }
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("{text:?}: give tx,ty,tz,qx,qy,qz,qw, `identity` or `z-up`"))?;
    let [tx, ty, tz, qx, qy, qz, qw] = values[..] else {
        return Err(format!(
            "{text:?} has {} numbers; a transform is tx,ty,tz,qx,qy,qz,qw",
            values.len()
        ));
    };
    let translation = DVec3::new(tx, ty, tz);
    if !translation.is_finite() {
        return Err(format!("{text:?}: the translation is not finite"));
    }
    Ok(rigid(
        rotation_from_quaternion(qx, qy, qz, qw)?,
        translation,
    ))
}

/// The 4×4 matrix of a transform, by rows (for manifests).
pub fn rows(t: &DAffine3) -> [[f64; 4]; 4] {
    let m = t.matrix3;
    let p = t.translation;
    [
        [m.x_axis.x, m.y_axis.x, m.z_axis.x, p.x],
        [m.x_axis.y, m.y_axis.y, m.z_axis.y, p.y],
        [m.x_axis.z, m.y_axis.z, m.z_axis.z, p.z],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Transforms parse from text and from rows; what is not rigid is refused, saying why.
    #[test]
    fn transforms_parse_and_refuse_what_is_not_rigid() {
        let t = parse_transform("1,2,3,0,0,0.7071068,0.7071068").unwrap();
        assert!(t.translation.abs_diff_eq(DVec3::new(1.0, 2.0, 3.0), 0.0));
        // 90° about z: x goes to y.
        assert!(t.matrix3.x_axis.abs_diff_eq(DVec3::Y, 1e-7));
        let up = parse_transform("z-up").unwrap();
        assert!(up.transform_vector3(DVec3::Z).abs_diff_eq(DVec3::Y, 1e-15));
        assert!(up.transform_vector3(DVec3::Y).abs_diff_eq(-DVec3::Z, 1e-15));
        assert!(parse_transform("1,2,3").unwrap_err().contains("3 numbers"));
        assert!(
            parse_transform("0,0,0,0,0,0,2")
                .unwrap_err()
                .contains("length 2")
        );
        let rows = vec![
            vec![0.0, -1.0, 0.0, 4.0],
            vec![1.0, 0.0, 0.0, 5.0],
            vec![0.0, 0.0, 1.0, 6.0],
            vec![0.0, 0.0, 0.0, 1.0],
        ];
        let t = rigid_from_rows(&rows).unwrap();
        // Through a quaternion and back: rounding only.
        let first = super::rows(&t)[0];
        for (a, b) in first.iter().zip([0.0, -1.0, 0.0, 4.0]) {
            assert!((a - b).abs() < 1e-15, "{first:?}");
        }
        let mut mirrored = rows.clone();
        mirrored[2][2] = -1.0;
        assert!(
            rigid_from_rows(&mirrored)
                .unwrap_err()
                .contains("determinant")
        );
        let mut scaled = rows.clone();
        scaled[0][1] = -2.0;
        assert!(rigid_from_rows(&scaled).unwrap_err().contains("RᵀR"));
        let mut projective = rows;
        projective[3][0] = 1.0;
        assert!(
            rigid_from_rows(&projective)
                .unwrap_err()
                .contains("last row")
        );
    }
}
