//! Reading input files within bounds. Every file a loader opens (OBJ, MTL, textures, scene
//! files, calibration files) comes through [`read`]: something other than a regular file (a
//! folder, a device such as `/dev/zero`, a named pipe, a socket) is refused before it is
//! opened, and so is a file larger than its kind's budget; reading stops at the budget even if
//! the file grows meanwhile. Without this, `mtllib /dev/zero` read until the machine's memory
//! ran out, and a named pipe blocked forever.

use std::io::Read;
use std::path::Path;

/// The environment variable that sets every kind's budget, in MiB, for people with huge
/// scenes (or, lower, to test the limits).
pub const BUDGET_VARIABLE: &str = "FISHEYE_MAX_INPUT_MIB";

/// The kinds of input file, each with a budget of bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputKind {
    /// Wavefront OBJ geometry: 1 GiB (about 15 M triangles of text; far more than one storage
    /// binding holds on most adapters).
    Obj,
    /// An OBJ's material library: 16 MiB.
    Mtl,
    /// A texture image (PNG): 256 MiB on disk (decoded size is bounded by the decoder's own
    /// limits).
    Texture,
    /// A scene file (TOML): 16 MiB.
    SceneFile,
    /// A camera calibration file (YAML, XML, JSON, text): 16 MiB.
    Calibration,
    /// A trajectory of poses (TUM, KITTI, EuRoC text): 256 MiB (a day of poses at 200 Hz).
    Trajectory,
    /// A glTF file (`.gltf` JSON or `.glb`) or one of its external buffers: 1 GiB, as OBJ.
    Gltf,
    /// A lens prescription (a table of surfaces): 1 MiB.
    Prescription,
}

impl InputKind {
    /// What the kind is called in messages.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Obj => "OBJ files",
            InputKind::Mtl => "MTL files",
            InputKind::Texture => "textures",
            InputKind::SceneFile => "scene files",
            InputKind::Calibration => "calibration files",
            InputKind::Trajectory => "trajectories",
            InputKind::Gltf => "glTF files and buffers",
            InputKind::Prescription => "lens prescriptions",
        }
    }

    /// The budget without [`BUDGET_VARIABLE`], in bytes.
    pub fn default_budget(self) -> u64 {
        const MIB: u64 = 1 << 20;
        match self {
            InputKind::Obj | InputKind::Gltf => 1024 * MIB,
            InputKind::Texture | InputKind::Trajectory => 256 * MIB,
            InputKind::Mtl | InputKind::SceneFile | InputKind::Calibration => 16 * MIB,
            InputKind::Prescription => MIB,
        }
    }

    /// The budget in bytes: [`BUDGET_VARIABLE`]'s MiB where it is set (an error where it is
    /// not a whole number), else [`InputKind::default_budget`].
    pub fn budget(self) -> std::io::Result<u64> {
        match std::env::var(BUDGET_VARIABLE) {
            Ok(text) => text
                .trim()
                .parse::<u64>()
                .ok()
                .and_then(|mib| mib.checked_mul(1 << 20))
                .ok_or_else(|| {
                    std::io::Error::other(format!(
                        "{BUDGET_VARIABLE}={text:?}: give the budget as a whole number of MiB"
                    ))
                }),
            Err(_) => Ok(self.default_budget()),
        }
    }
}

/// Reads the file at `path` as `kind`, within its budget (see the module's documentation).
/// The error says what is wrong without the path, which the caller names.
pub fn read(path: &Path, kind: InputKind) -> std::io::Result<Vec<u8>> {
    read_within(path, kind, kind.budget()?)
}

/// As [`read`], with the budget given.
pub fn read_within(path: &Path, kind: InputKind, budget: u64) -> std::io::Result<Vec<u8>> {
    // Before opening: opening a named pipe waits for a writer.
    refuse_special(&std::fs::metadata(path)?)?;
    let mut file = open_without_waiting(path)?;
    // The file opened may not be the one looked at; its own metadata settles it.
    let meta = file.metadata()?;
    refuse_special(&meta)?;
    let over = |size: String| {
        std::io::Error::other(format!(
            "{size}, over the {} budget for {} ({BUDGET_VARIABLE} sets it, in MiB)",
            bytes(budget),
            kind.name()
        ))
    };
    if meta.len() > budget {
        return Err(over(bytes(meta.len())));
    }
    let mut out = Vec::with_capacity(meta.len() as usize);
    (&mut file).take(budget + 1).read_to_end(&mut out)?;
    if out.len() as u64 > budget {
        return Err(over("grew while read".into()));
    }
    Ok(out)
}

#[cfg(unix)]
fn open_without_waiting(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

#[cfg(not(unix))]
fn open_without_waiting(path: &Path) -> std::io::Result<std::fs::File> {
    std::fs::File::open(path)
}

/// An error for anything but a regular file, saying what it is.
fn refuse_special(meta: &std::fs::Metadata) -> std::io::Result<()> {
    if meta.is_file() {
        return Ok(());
    }
    Err(std::io::Error::other(format!(
        "{}, not a regular file",
        what_it_is(meta)
    )))
}

/// What a file that is not a regular one is, in words.
pub fn what_it_is(meta: &std::fs::Metadata) -> &'static str {
    let kind = meta.file_type();
    if kind.is_dir() {
        return "a folder";
    }
    if kind.is_symlink() {
        return "a symbolic link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_fifo() {
            return "a named pipe";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    "not a plain file"
}

/// A size in bytes, KiB, MiB or GiB, for messages.
fn bytes(n: u64) -> String {
    match n {
        0..1024 => format!("{n} bytes"),
        1024..1_048_576 => format!("{:.1} KiB", n as f64 / 1024.0),
        1_048_576..1_073_741_824 => format!("{:.1} MiB", n as f64 / 1_048_576.0),
        _ => format!("{:.1} GiB", n as f64 / 1_073_741_824.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refused(path: &Path, budget: u64) -> String {
        read_within(path, InputKind::Obj, budget)
            .unwrap_err()
            .to_string()
    }

    /// Special files are refused before they are opened (a pipe would block, a device never
    /// end), whatever the budget; files over the budget are refused with both sizes.
    #[test]
    fn special_and_oversized_files_are_refused_saying_why() {
        let dir = std::env::temp_dir().join(format!("fisheye-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert_eq!(refused(&dir, u64::MAX), "a folder, not a regular file");
        assert_eq!(
            refused(Path::new("/dev/zero"), u64::MAX),
            "a device, not a regular file"
        );
        let fifo = dir.join("pipe.obj");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(status.success());
        assert_eq!(refused(&fifo, u64::MAX), "a named pipe, not a regular file");
        let link = dir.join("zero.obj");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        assert_eq!(refused(&link, u64::MAX), "a device, not a regular file");

        let file = dir.join("big.obj");
        std::fs::write(&file, vec![b'#'; 3000]).unwrap();
        assert_eq!(
            refused(&file, 2048),
            "2.9 KiB, over the 2.0 KiB budget for OBJ files (FISHEYE_MAX_INPUT_MIB sets it, in MiB)"
        );
        assert_eq!(
            read_within(&file, InputKind::Obj, 3000).unwrap().len(),
            3000
        );
        assert!(refused(&dir.join("missing.obj"), 1).contains("No such file"));
        // A file longer than its metadata says (as one growing while it is read): /proc's
        // files are regular, report 0 bytes and read as hundreds. Reading stops at the budget.
        assert_eq!(std::fs::metadata("/proc/self/status").unwrap().len(), 0);
        assert_eq!(
            refused(Path::new("/proc/self/status"), 100),
            "grew while read, over the 100 bytes budget for OBJ files (FISHEYE_MAX_INPUT_MIB sets it, in MiB)"
        );
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn sizes_read_in_their_unit() {
        assert_eq!(bytes(1023), "1023 bytes");
        assert_eq!(bytes(16 << 20), "16.0 MiB");
        assert_eq!(bytes(3 << 30), "3.0 GiB");
    }
}
