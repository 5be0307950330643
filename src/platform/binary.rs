//! The file this code was loaded from: the executable, or — when vibrobed runs inside another
//! program, as the Python package's extension module does — the shared library that holds it.
//! A checkpoint names its build by this file's bytes.

use std::path::PathBuf;

/// The shared library holding this code, else the executable.
pub fn own_file() -> Option<PathBuf> {
    shared_library().or_else(|| std::env::current_exe().ok())
}

/// The shared library (`*.so`) holding this function, if it is in one.
#[cfg(target_os = "linux")]
fn shared_library() -> Option<PathBuf> {
    use std::ffi::{CStr, OsStr};
    use std::os::unix::ffi::OsStrExt;
    // SAFETY: `Dl_info` is plain data; dladdr only reads the loader's tables for an address
    // of this library's code and fills it, its name pointing into the loader's own memory.
    let name = unsafe {
        let mut info: libc::Dl_info = std::mem::zeroed();
        let found = libc::dladdr(shared_library as *const libc::c_void, &mut info);
        if found == 0 || info.dli_fname.is_null() {
            return None;
        }
        CStr::from_ptr(info.dli_fname).to_bytes().to_vec()
    };
    let path = PathBuf::from(OsStr::from_bytes(&name));
    let library = path.extension().is_some_and(|e| e == "so");
    library.then_some(path)
}

#[cfg(not(target_os = "linux"))]
fn shared_library() -> Option<PathBuf> {
    None
}
