//! Input files a scene names (meshes, textures, environment maps,
//! references, the scene itself) must be regular files: a FIFO would block
//! the reader forever, a device such as `/dev/zero` never ends, and a
//! folder cannot be read. [`check_regular_file`] says which of these a
//! path is before anything opens it; the loaders call it first.

use std::path::Path;

/// `Ok` if `path` names a regular file (through symbolic links), else a
/// sentence that names the path and says what it is instead.
pub fn check_regular_file(path: &Path) -> Result<(), String> {
    let meta =
        std::fs::metadata(path).map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
    if meta.is_file() {
        return Ok(());
    }
    Err(format!(
        "`{}` is {}, not a regular file",
        path.display(),
        kind_of(&meta)
    ))
}

/// `Ok` if `path` is a regular file or does not exist (its reader then
/// reports the missing file in its own words), else as
/// [`check_regular_file`]: for loaders that open the file right after.
pub fn reject_special_file(path: &Path) -> Result<(), String> {
    if path.exists() {
        check_regular_file(path)
    } else {
        Ok(())
    }
}

/// What a non-regular file is, with its article.
fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    if meta.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "a special file"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_pass_and_others_are_named() {
        let dir = std::env::temp_dir();
        let file = dir.join(format!("radiant-input-{}.txt", std::process::id()));
        std::fs::write(&file, "x").expect("temp file");
        assert_eq!(check_regular_file(&file), Ok(()));
        std::fs::remove_file(&file).expect("removed");
        let folder = check_regular_file(&dir).expect_err("a folder");
        assert!(folder.contains("is a folder"), "{folder}");
        #[cfg(unix)]
        {
            let zero = check_regular_file(Path::new("/dev/zero")).expect_err("a device");
            assert!(zero.contains("character device"), "{zero}");
        }
        let missing = check_regular_file(Path::new("/nonexistent/x.obj")).expect_err("missing");
        assert!(
            missing.contains("cannot read `/nonexistent/x.obj`"),
            "{missing}"
        );
    }
}
