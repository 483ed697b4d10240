//! Input files a scene names (meshes, textures, environment maps,
//! references, the scene itself) must be regular files: a FIFO would block
//! the reader forever, a device such as `/dev/zero` never ends, and a
//! folder cannot be read. [`reject_special_file`] says which of these a
//! path is before anything opens it; the loaders call it first.

use std::path::Path;

/// `Ok` if `path` is a regular file (through symbolic links) or cannot be
/// looked at (missing: its reader then reports that in its own words),
/// else a sentence that names the path and says what it is instead.
pub fn reject_special_file(path: &Path) -> Result<(), String> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => Err(format!(
            "`{}` is {}, not a regular file",
            path.display(),
            kind_of(&meta)
        )),
        _ => Ok(()),
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
        assert_eq!(reject_special_file(&file), Ok(()));
        std::fs::remove_file(&file).expect("removed");
        let folder = reject_special_file(&dir).expect_err("a folder");
        assert!(folder.contains("is a folder"), "{folder}");
        #[cfg(unix)]
        {
            let zero = reject_special_file(Path::new("/dev/zero")).expect_err("a device");
            assert!(zero.contains("character device"), "{zero}");
        }
        // A missing file is left to its reader.
        assert_eq!(reject_special_file(Path::new("/nonexistent/x.obj")), Ok(()));
    }
}
