//! Reading input files safely: only regular files (a FIFO would block, a device never end), of
//! bounded size, as UTF-8 text.

use std::io::Read;
use std::path::Path;

/// Reads the regular file at `path` (links followed) as text, refusing anything else and
/// anything longer than `max_bytes`; the error says which.
pub fn read_regular_text(path: &Path, max_bytes: u64) -> std::io::Result<String> {
    use std::io::{Error, ErrorKind};
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            "not a regular file (a directory, FIFO, device or socket)",
        ));
    }
    if meta.len() > max_bytes {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("{} bytes, more than the {max_bytes} accepted", meta.len()),
        ));
    }
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(max_bytes + 1)
        .read_to_string(&mut text)?;
    if text.len() as u64 > max_bytes {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("grew beyond the {max_bytes} bytes accepted while being read"),
        ));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_bounded_regular_files_are_read() {
        let dir = std::env::temp_dir().join(format!("mergesim-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("a.toml");
        std::fs::write(&file, "x = 1\n").unwrap();
        assert_eq!(read_regular_text(&file, 100).unwrap(), "x = 1\n");
        let err = read_regular_text(&file, 3).unwrap_err().to_string();
        assert!(err.contains("more than the 3"), "{err}");
        let err = read_regular_text(&dir, 100).unwrap_err().to_string();
        assert!(err.contains("not a regular file"), "{err}");
        #[cfg(unix)]
        {
            let err = read_regular_text(Path::new("/dev/zero"), 100)
                .unwrap_err()
                .to_string();
            assert!(err.contains("not a regular file"), "{err}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
