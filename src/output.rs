//! Output files: checked before any work, written whole or not at all, never replacing anything
//! but a regular file.

use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically: into a temporary file beside it, then renamed, so a
/// reader (or a crash) never sees half a file. The temporary file is removed on failure.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = temporary_path(path);
    let result = (|| {
        let mut file = create_temporary(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Creates `tmp` afresh, never following a link left at its name (a stale temporary file of
/// a killed process is removed first).
fn create_temporary(tmp: &Path) -> std::io::Result<std::fs::File> {
    match OpenOptions::new().write(true).create_new(true).open(tmp) {
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
            std::fs::remove_file(tmp)?;
            OpenOptions::new().write(true).create_new(true).open(tmp)
        }
        other => other,
    }
}

/// `dir/name` → `dir/.name.<pid>.tmp` (the process id keeps concurrent writers apart).
pub fn temporary_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// What kind of file system entry `meta` describes, for messages.
fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "directory";
    }
    if t.is_symlink() {
        return "symbolic link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "FIFO";
        }
        if t.is_socket() {
            return "socket";
        }
        if t.is_block_device() || t.is_char_device() {
            return "device";
        }
    }
    "special file"
}

/// Checks before a long run that `path` can be written: it is not an existing directory, link,
/// device, FIFO or socket (mergesim only ever replaces regular files), not a read-only file,
/// and its folder exists and lets this process create files. So a bad path fails in
/// milliseconds with exit code 2, not after the simulation, and nothing that is not ours is
/// replaced.
pub fn check_output_path(path: &Path, what: &str) -> Result<(), String> {
    if path.as_os_str().is_empty() {
        return Err(format!("{what}: empty path"));
    }
    if path
        .as_os_str()
        .to_string_lossy()
        .ends_with(std::path::is_separator)
    {
        return Err(format!(
            "{what} {}: ends with a path separator, so it names a folder, not a file",
            path.display()
        ));
    }
    match std::fs::symlink_metadata(path) {
        Ok(meta) if !meta.file_type().is_file() => {
            return Err(format!(
                "{what} {}: exists and is a {}, not a regular file; mergesim only replaces \
                 regular files (choose another path)",
                path.display(),
                kind_of(&meta)
            ));
        }
        Ok(meta) if meta.permissions().readonly() => {
            return Err(format!(
                "{what} {}: exists and is read-only; not replacing it (choose another path or \
                 make it writable)",
                path.display()
            ));
        }
        _ => {}
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        return Err(format!(
            "{what} {}: folder {} does not exist",
            path.display(),
            parent.display()
        ));
    }
    // Probe the folder with the temporary file the write will use.
    let probe = temporary_path(path);
    match create_temporary(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(format!(
            "{what} {}: cannot create files in folder {}: {e}",
            path.display(),
            parent.display()
        )),
    }
}

/// Where `path` (an output, which may not exist yet) would be: its folder resolved (links,
/// `..`) and its file name; `None` if the folder cannot be resolved.
fn resolved_output(path: &Path) -> Option<PathBuf> {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(parent).ok()?.join(path.file_name()?))
}

/// Checks that no two outputs are the same file and that no output is one of the inputs
/// (`outputs`: path and option name; `inputs`: files read): writing one would destroy the
/// other. Paths are compared after resolving links and `..`.
pub fn check_distinct(outputs: &[(&Path, &str)], inputs: &[&Path]) -> Result<(), String> {
    let resolved: Vec<(Option<PathBuf>, &Path, &str)> = outputs
        .iter()
        .map(|(path, what)| (resolved_output(path), *path, *what))
        .collect();
    for (i, (a, path_a, what_a)) in resolved.iter().enumerate() {
        let Some(a) = a else { continue };
        for (b, _, what_b) in &resolved[..i] {
            if b.as_ref() == Some(a) {
                return Err(format!(
                    "{what_a} {}: the same file as {what_b}; give each output its own path",
                    path_a.display()
                ));
            }
        }
        for input in inputs {
            if std::fs::canonicalize(input).ok().as_ref() == Some(a) {
                return Err(format!(
                    "{what_a} {}: is the input file {}; writing it would destroy it",
                    path_a.display(),
                    input.display()
                ));
            }
        }
    }
    Ok(())
}

/// A name from a scenario (or planner) made safe as part of a file name in the output folder:
/// characters other than ASCII letters, digits, `-`, `_` and `.` become `_`, leading dots are
/// dropped (no hidden files, no `..`), at most 100 characters; empty gives `unnamed`.
pub fn file_name_part(name: &str) -> String {
    let mapped: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    let trimmed: String = mapped.trim_start_matches('.').chars().take(100).collect();
    if trimmed.is_empty() {
        "unnamed".into()
    } else {
        trimmed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_must_differ_from_each_other_and_from_the_inputs() {
        let dir = std::env::temp_dir().join(format!("mergesim-distinct-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let input = dir.join("scenario.toml");
        std::fs::write(&input, "").unwrap();
        let a = dir.join("a.json");
        let a_again = dir.join("sub/../a.json");
        assert!(
            check_distinct(&[(&a, "--json"), (&dir.join("b.csv"), "--csv")], &[&input]).is_ok()
        );
        let err = check_distinct(&[(&a, "--json"), (&a_again, "--csv")], &[]).unwrap_err();
        assert!(
            err.contains("--csv") && err.contains("same file as --json"),
            "{err}"
        );
        let err = check_distinct(&[(&input, "--json")], &[&input]).unwrap_err();
        assert!(err.contains("input file"), "{err}");
        let err = check_output_path(Path::new("x.json/"), "--json").unwrap_err();
        assert!(err.contains("names a folder"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn names_from_scenarios_stay_in_the_folder() {
        assert_eq!(file_name_part("urgent_merge"), "urgent_merge");
        assert_eq!(file_name_part("../x"), "_x");
        assert_eq!(file_name_part("/etc/passwd"), "_etc_passwd");
        assert_eq!(file_name_part("..."), "unnamed");
        assert_eq!(file_name_part("a b\\c\n"), "a_b_c_");
        assert_eq!(file_name_part(&"x".repeat(300)).len(), 100);
    }

    #[test]
    fn only_regular_writable_files_are_replaced() {
        let dir = std::env::temp_dir().join(format!("mergesim-output-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("a.json");
        std::fs::write(&file, "old").unwrap();
        assert!(check_output_path(&file, "--json").is_ok());
        let err = check_output_path(&dir, "--json").unwrap_err();
        assert!(err.contains("directory"), "{err}");
        #[cfg(unix)]
        {
            let link = dir.join("link.json");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(&file, &link).unwrap();
            let err = check_output_path(&link, "--json").unwrap_err();
            assert!(err.contains("symbolic link"), "{err}");
            let err = check_output_path(Path::new("/dev/null"), "--json").unwrap_err();
            assert!(err.contains("device"), "{err}");
        }
        let mut perms = std::fs::metadata(&file).unwrap().permissions();
        perms.set_readonly(true);
        std::fs::set_permissions(&file, perms).unwrap();
        let err = check_output_path(&file, "--json").unwrap_err();
        assert!(err.contains("read-only"), "{err}");
        let err = check_output_path(&dir.join("no/such/x.json"), "--json").unwrap_err();
        assert!(err.contains("does not exist"), "{err}");
        // Nothing left behind by the probes.
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
        // A stale temporary link is replaced, never written through.
        #[cfg(unix)]
        {
            let target = dir.join("target.txt");
            std::fs::write(&target, "keep").unwrap();
            let out = dir.join("b.json");
            let _ = std::fs::remove_file(temporary_path(&out));
            std::os::unix::fs::symlink(&target, temporary_path(&out)).unwrap();
            write_atomically(&out, b"new").unwrap();
            assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
            assert_eq!(std::fs::read_to_string(&out).unwrap(), "new");
        }
        let mut perms = std::fs::metadata(&file).unwrap().permissions();
        #[allow(clippy::permissions_set_readonly_false)]
        perms.set_readonly(false);
        std::fs::set_permissions(&file, perms).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
