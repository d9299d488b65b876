//! Reading a file that a user, a scene file or a model names, as untrusted input: it
//! must be a regular file, found by kind on the handle that is read (so nothing can
//! be swapped in between the check and the read), and it is read only up to the
//! length it states and a limit the caller gives. A FIFO is refused without waiting
//! for a writer; `/proc/self/pagemap`, which states a length of 0 and reads without
//! end, reads as empty.

use std::{
    fs::{File, Metadata},
    io::Read,
    path::Path,
};

/// Whether the last component of the path may be a symbolic link.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Links {
    /// Follow it: a model or a scene file the user named, which may be a link.
    Follow,
    /// Refuse it: a file Gnomon wrote itself (a cache entry), which is never a link
    /// unless someone else planted one.
    Refuse,
}

/// Why a file was not read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// Nothing at the path.
    #[error("no such file")]
    Missing,
    /// A directory, a FIFO, a device, a socket, or a link where links are refused.
    #[error("it is {0}, not a regular file")]
    NotRegular(&'static str),
    /// The file states more bytes than the caller takes.
    #[error("the file is {}; {what} may be at most {}", crate::gltf_loader::sources::size(*.bytes), crate::gltf_loader::sources::size(*.limit))]
    TooLarge {
        /// The file's stated length.
        bytes: u64,
        /// The caller's limit.
        limit: u64,
        /// What the file is (`a model`, `a scene file`).
        what: &'static str,
    },
    /// Any other failure to open or read.
    #[error("cannot read: {0}")]
    Io(#[from] std::io::Error),
}

/// Opens `path` for reading if it is a regular file, and returns it with its
/// metadata as the open handle sees it.
pub fn open_regular(path: &Path, links: Links) -> Result<(File, Metadata), ReadError> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // O_NONBLOCK: opening a FIFO returns at once instead of waiting for a writer;
        // the kind check below then refuses it. Regular files ignore the flag.
        let no_follow = if links == Links::Refuse { libc::O_NOFOLLOW } else { 0 };
        options.custom_flags(libc::O_NONBLOCK | no_follow);
    }
    let file = options.open(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => ReadError::Missing,
        // O_NOFOLLOW on a link fails with ELOOP.
        _ if links == Links::Refuse && std::fs::symlink_metadata(path).is_ok_and(|m| m.is_symlink()) => {
            ReadError::NotRegular("a symbolic link")
        }
        _ => ReadError::Io(e),
    })?;
    let metadata = file.metadata()?;
    if !metadata.is_file() {
        return Err(ReadError::NotRegular(crate::gltf_loader::sources::file_kind(&metadata)));
    }
    Ok((file, metadata))
}

/// The bytes of the regular file at `path`: at most its stated length, which must be
/// at most `limit` (`what` names the file in the error: `a model`).
pub fn read_regular(path: &Path, links: Links, limit: u64, what: &'static str) -> Result<Vec<u8>, ReadError> {
    let (file, metadata) = open_regular(path, links)?;
    let bytes = metadata.len();
    if bytes > limit {
        return Err(ReadError::TooLarge { bytes, limit, what });
    }
    let mut out = Vec::with_capacity(bytes as usize);
    // `take`: a file that grows while it is read (or a pseudo file that states 0)
    // gives no more than it stated.
    file.take(bytes).read_to_end(&mut out)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_is_named_for_what_it_is() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_regular(dir.path(), Links::Follow, 10, "a model").unwrap_err();
        assert!(matches!(e, ReadError::NotRegular("a directory")), "{e:?}");
        let e = read_regular(&dir.path().join("none"), Links::Follow, 10, "a model").unwrap_err();
        assert!(matches!(e, ReadError::Missing), "{e:?}");
    }

    #[test]
    fn a_file_past_the_limit_is_refused_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big");
        std::fs::write(&path, [0u8; 100]).unwrap();
        let e = read_regular(&path, Links::Follow, 99, "a scene file").unwrap_err().to_string();
        assert!(e.contains("100 bytes") && e.contains("a scene file may be at most 99 bytes"), "{e}");
        assert_eq!(read_regular(&path, Links::Follow, 100, "x").unwrap().len(), 100);
    }

    /// A FIFO with no writer is refused at once (it would block a plain read), and a
    /// pseudo file that states no length reads as empty, not forever.
    #[cfg(target_os = "linux")]
    #[test]
    fn special_files_are_refused_or_read_to_their_stated_length() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("fifo");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let e = read_regular(&fifo, Links::Follow, 10, "a model").unwrap_err();
        assert!(matches!(e, ReadError::NotRegular("a FIFO")), "{e:?}");
        let pagemap = read_regular(Path::new("/proc/self/pagemap"), Links::Follow, 1 << 30, "a model");
        assert_eq!(pagemap.unwrap().len(), 0, "states 0 bytes, so 0 are read");
    }

    #[cfg(unix)]
    #[test]
    fn a_link_is_followed_or_refused_as_asked() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real");
        std::fs::write(&real, "abc").unwrap();
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        assert_eq!(read_regular(&link, Links::Follow, 10, "x").unwrap(), b"abc");
        let e = read_regular(&link, Links::Refuse, 10, "x").unwrap_err();
        assert!(matches!(e, ReadError::NotRegular("a symbolic link")), "{e:?}");
    }
}
