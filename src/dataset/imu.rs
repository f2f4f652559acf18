//! A synthetic IMU on the body ([`measure`]): its angular rate and specific force from the
//! trajectory's smooth spline ([`Spline`]), with white noise and bias random walks as Kalibr's
//! `imu.yaml` states them ([`ImuNoise`]), written in EuRoC's `imu0/data.csv` layout.
//!
//! The IMU's frame is the body's (a Kalibr camchain's `T_cam_imu` puts the cameras on it; see
//! `lens::calib::read_rig`). Specific force is what an accelerometer reads:
//! f = Rᵀ (a - g), with g the world's gravity (default 9.81 m/s² down the world's z, the
//! convention of EuRoC and TUM trajectories). Noise is Kalibr's continuous-time model
//! discretised at the update rate Δt (Kalibr's wiki, "IMU Noise Model"): white noise of
//! standard deviation σ/√Δt, and a bias that walks by σ_b·√Δt each sample.

use std::path::Path;

use glam::DVec3;

use super::smooth::Spline;
use crate::error::{Error, Result};
use crate::lens::calib::{load_yaml, yaml_number};

/// Kalibr's IMU noise parameters (`imu.yaml`), in its continuous-time units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuNoise {
    /// m/s²/√Hz.
    pub accelerometer_noise_density: f64,
    /// m/s³/√Hz.
    pub accelerometer_random_walk: f64,
    /// rad/s/√Hz.
    pub gyroscope_noise_density: f64,
    /// rad/s²/√Hz.
    pub gyroscope_random_walk: f64,
    /// Hz.
    pub update_rate: f64,
}

impl ImuNoise {
    /// The key names, in the order of the fields.
    const KEYS: [&'static str; 5] = [
        "accelerometer_noise_density",
        "accelerometer_random_walk",
        "gyroscope_noise_density",
        "gyroscope_random_walk",
        "update_rate",
    ];

    /// Reads a Kalibr `imu.yaml`; errors name the file and the key.
    pub fn read(path: &Path) -> Result<Self> {
        let bad = |message: String| Error::Dataset {
            path: path.to_path_buf(),
            message,
        };
        let bytes = crate::input::read(path, crate::input::InputKind::Calibration)
            .map_err(|e| bad(format!("cannot read the IMU's noise: {e}")))?;
        let yaml = load_yaml(&String::from_utf8_lossy(&bytes)).map_err(bad)?;
        let mut values = [0.0; 5];
        for (value, key) in values.iter_mut().zip(Self::KEYS) {
            *value = yaml_number(&yaml[key])
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| {
                    bad(format!(
                        "{key} is missing or not a number of 0 or more (Kalibr's imu.yaml \
                         holds {})",
                        Self::KEYS.join(", ")
                    ))
                })?;
        }
        if values[4] == 0.0 {
            return Err(bad("update_rate is 0 Hz".into()));
        }
        let [a, ab, g, gb, rate] = values;
        Ok(Self {
            accelerometer_noise_density: a,
            accelerometer_random_walk: ab,
            gyroscope_noise_density: g,
            gyroscope_random_walk: gb,
            update_rate: rate,
        })
    }
}

/// A synthetic IMU as a dataset renders it: the spline it reads (which the frames follow
/// too), its rate, its noise, the noise's seed and the world's gravity.
#[derive(Clone, Debug)]
pub struct Imu {
    /// The trajectory's spline.
    pub spline: Spline,
    /// Samples a second.
    pub rate: f64,
    /// Kalibr's noise model; `None`: noise-free readings only.
    pub noise: Option<ImuNoise>,
    /// The noise's seed.
    pub seed: u64,
    /// Gravity in the trajectory's world, m/s².
    pub gravity: DVec3,
}

/// Where an IMU's readings go in a dataset's folder: as a real IMU reads them (with noise,
/// where a model is given), and noise-free.
pub const IMU_FILES: [&str; 2] = ["imu0/data.csv", "imu0/data_noise_free.csv"];

impl Imu {
    /// Writes [`IMU_FILES`] into `folder`, time stamps in integer nanoseconds counted from the
    /// trajectory's `first` pose (its EuRoC stamp as written, else its seconds).
    pub fn write(
        &self,
        folder: &Path,
        first: Option<&super::trajectory::Pose>,
        format: super::trajectory::TrajectoryFormat,
    ) -> Result<()> {
        let first_seconds = first.map_or(0.0, |p| p.seconds);
        let first_ns = first
            .filter(|_| format == super::trajectory::TrajectoryFormat::Euroc)
            .and_then(|p| p.stamp.parse::<i128>().ok())
            .unwrap_or_else(|| (first_seconds * 1e9).round() as i128);
        let clean = measure(&self.spline, self.rate, self.gravity);
        let read = match &self.noise {
            Some(noise) => with_noise(&clean, noise, self.seed),
            None => clean.clone(),
        };
        for (file, samples) in IMU_FILES.iter().zip([&read, &clean]) {
            let text = euroc_csv(samples, first_seconds, first_ns);
            crate::trace::write_file(&folder.join(file), text.as_bytes())?;
        }
        Ok(())
    }
}

/// One IMU sample: its time (seconds, the trajectory's clock), angular rate (rad/s) and
/// specific force (m/s²), both in the IMU's (body's) frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Seconds.
    pub seconds: f64,
    /// Angular rate.
    pub gyro: DVec3,
    /// Specific force.
    pub accel: DVec3,
}

/// The noise-free samples at `rate` Hz over the spline's span, from its start.
pub fn measure(spline: &Spline, rate: f64, gravity: DVec3) -> Vec<Sample> {
    let (first, last) = spline.span();
    let count = ((last - first) * rate * (1.0 + 1e-12)).floor() as usize + 1;
    (0..count)
        .filter_map(|k| {
            let seconds = (first + k as f64 / rate).min(last);
            let m = spline.at(seconds)?;
            let to_body = m.pose.matrix3.transpose();
            Some(Sample {
                seconds,
                gyro: m.rate,
                accel: to_body * (m.acceleration - gravity),
            })
        })
        .collect()
}

/// Normal deviates from a seed: splitmix64 (Steele, Lea and Flood, "Fast Splittable
/// Pseudorandom Number Generators", OOPSLA 2014) for uniforms, Box–Muller for normals.
struct Normals(u64);

impl Normals {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        // In (0, 1]: 53 bits, never 0.
        ((z >> 11) + 1) as f64 / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    fn vector(&mut self) -> DVec3 {
        DVec3::new(self.normal(), self.normal(), self.normal())
    }
}

/// `samples` as a real IMU at `noise`'s densities reads them, the biases starting at zero;
/// the same `seed` gives the same noise. The noise is discretised at `noise.update_rate`.
pub fn with_noise(samples: &[Sample], noise: &ImuNoise, seed: u64) -> Vec<Sample> {
    let dt = 1.0 / noise.update_rate;
    let mut normals = Normals(seed);
    let (mut gyro_bias, mut accel_bias) = (DVec3::ZERO, DVec3::ZERO);
    samples
        .iter()
        .map(|s| {
            let sample = Sample {
                seconds: s.seconds,
                gyro: s.gyro
                    + gyro_bias
                    + normals.vector() * noise.gyroscope_noise_density / dt.sqrt(),
                accel: s.accel
                    + accel_bias
                    + normals.vector() * noise.accelerometer_noise_density / dt.sqrt(),
            };
            gyro_bias += normals.vector() * noise.gyroscope_random_walk * dt.sqrt();
            accel_bias += normals.vector() * noise.accelerometer_random_walk * dt.sqrt();
            sample
        })
        .collect()
}

/// The samples as EuRoC's `imu0/data.csv`: a header, then the time stamp in integer
/// nanoseconds (`first_ns` at `first_seconds`, counted from there) and the angular rate and
/// specific force, comma-separated.
pub fn euroc_csv(samples: &[Sample], first_seconds: f64, first_ns: i128) -> String {
    let mut text = String::from(
        "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],\
         a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n",
    );
    for s in samples {
        let ns = first_ns + ((s.seconds - first_seconds) * 1e9).round() as i128;
        let (w, a) = (s.gyro, s.accel);
        text += &format!("{ns},{},{},{},{},{},{}\n", w.x, w.y, w.z, a.x, a.y, a.z);
    }
    text
}

#[cfg(test)]
mod tests;
