//! Denoising with Intel Open Image Denoise (OIDN), loaded at run time.
//!
//! Data flow: a render that asks for `--denoise` collects the albedo and
//! normal planes ([`super::aov`]) beside the image; [`Denoiser::denoise`]
//! hands the three to OIDN's `RT` filter (HDR colour, albedo and normal
//! guides) and returns the denoised image, which is written as usual.
//!
//! The library is opened with `dlopen` (libloading) through a few entry
//! points of its C API rather than linked: the default build needs nothing,
//! and a machine without OIDN renders everything else and says, for
//! `--denoise` alone, how to get it. It is looked for at the path (a file or
//! its folder) in `RADIANT_OIDN`, then as `libOpenImageDenoise.so.2` on the
//! system's library path. Debian has no package of it; the PyPI wheel
//! `pyoidn` ships the library (`pip install pyoidn`, see README).
//!
//! Guides: first-hit albedo and normals carry no sampling noise where the
//! camera has no aperture and nothing moves (the albedo estimate of a point
//! is deterministic, so only anti-aliasing varies), and OIDN is told
//! `cleanAux`; with depth of field or motion blur they are noisy and are
//! *prefiltered* — each denoised alone by the `RT` filter first, as OIDN's
//! documentation recommends.

use super::Image;
use super::aov::AovImage;
use crate::extract::RenderScene;
use radiant_core::{Effects, Rgb};
use std::ffi::{CStr, CString, c_char, c_void};
use std::path::{Path, PathBuf};

/// The environment variable naming the OIDN library (or its folder).
pub const LIBRARY_ENV: &str = "RADIANT_OIDN";

/// The library's file name (OIDN 2's C API).
const LIBRARY_NAME: &str = "libOpenImageDenoise.so.2";

/// What went wrong finding or running the denoiser.
#[derive(Debug, thiserror::Error)]
pub enum DenoiseError {
    /// The library could not be loaded.
    #[error(
        "--denoise needs Intel Open Image Denoise 2 ({LIBRARY_NAME}), which could not be loaded: \
         {detail}. Install it with `pip install pyoidn` and point {LIBRARY_ENV} at its library \
         folder: export {LIBRARY_ENV}=\"$(python3 -c 'import importlib.util as u, pathlib; \
         print(pathlib.Path(u.find_spec(\"pyoidn\").origin).parent / \"oidn/lib\")')\" \
         (or put that folder on LD_LIBRARY_PATH)"
    )]
    NotFound {
        /// Where it was looked for and why each failed.
        detail: String,
    },
    /// OIDN reported an error.
    #[error("Open Image Denoise failed: {0}")]
    Failed(String),
}

type Handle = *mut c_void;

/// The entry points of OIDN's C API that Radiant calls.
struct Api {
    new_device: unsafe extern "C" fn(i32) -> Handle,
    commit_device: unsafe extern "C" fn(Handle),
    release_device: unsafe extern "C" fn(Handle),
    device_error: unsafe extern "C" fn(Handle, *mut *const c_char) -> i32,
    new_filter: unsafe extern "C" fn(Handle, *const c_char) -> Handle,
    set_image: unsafe extern "C" fn(
        Handle,
        *const c_char,
        *mut c_void,
        i32,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    set_bool: unsafe extern "C" fn(Handle, *const c_char, bool),
    commit_filter: unsafe extern "C" fn(Handle),
    execute_filter: unsafe extern "C" fn(Handle),
    release_filter: unsafe extern "C" fn(Handle),
}

/// `OIDN_DEVICE_TYPE_CPU`.
const DEVICE_CPU: i32 = 1;
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: i32 = 3;

/// A loaded OIDN library.
pub struct Denoiser {
    api: Api,
    /// Where it was loaded from.
    path: PathBuf,
    /// Keeps the entry points valid.
    _library: libloading::Library,
}

/// How the albedo and normal guides are handed to OIDN.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Guides {
    /// Noise-free guides (`cleanAux`).
    Clean,
    /// Noisy guides, denoised alone first.
    Prefilter,
}

impl Guides {
    /// The guides a frame of `scene` gives: noisy where its camera has an
    /// aperture or something moves while the shutter is open.
    pub fn of(scene: &RenderScene) -> Self {
        if scene
            .effects
            .intersects(Effects::DEPTH_OF_FIELD | Effects::MOTION_BLUR)
        {
            Guides::Prefilter
        } else {
            Guides::Clean
        }
    }
}

/// The places the library is looked for, in order.
fn candidates() -> Vec<PathBuf> {
    let mut paths = Vec::new();
    if let Some(path) = std::env::var_os(LIBRARY_ENV).filter(|p| !p.is_empty()) {
        let path = PathBuf::from(path);
        if path.is_dir() {
            paths.push(path.join(LIBRARY_NAME));
        } else {
            paths.push(path);
        }
    }
    paths.push(PathBuf::from(LIBRARY_NAME));
    paths
}

impl Denoiser {
    /// Loads OIDN from [`LIBRARY_ENV`] or the system's library path.
    pub fn load() -> Result<Self, DenoiseError> {
        let mut tried = Vec::new();
        for path in candidates() {
            // SAFETY: loading runs the library's initialisers; OIDN's are
            // those of a C++ library with no preconditions on the caller.
            match unsafe { libloading::Library::new(&path) } {
                Ok(library) => return Self::bind(library, path),
                Err(e) => tried.push(format!("{}: {e}", path.display())),
            }
        }
        Err(DenoiseError::NotFound {
            detail: tried.join("; "),
        })
    }

    /// Looks the entry points up in `library`.
    fn bind(library: libloading::Library, path: PathBuf) -> Result<Self, DenoiseError> {
        let missing = |e: libloading::Error| DenoiseError::NotFound {
            detail: format!("{}: {e} (is it OIDN 2?)", path.display()),
        };
        // SAFETY: each symbol is declared with its type in OIDN 2's
        // `oidn.h`; the pointers stay valid while `library` is loaded, which
        // the struct keeps.
        let api = unsafe {
            Api {
                new_device: *library.get(b"oidnNewDevice\0").map_err(missing)?,
                commit_device: *library.get(b"oidnCommitDevice\0").map_err(missing)?,
                release_device: *library.get(b"oidnReleaseDevice\0").map_err(missing)?,
                device_error: *library.get(b"oidnGetDeviceError\0").map_err(missing)?,
                new_filter: *library.get(b"oidnNewFilter\0").map_err(missing)?,
                set_image: *library
                    .get(b"oidnSetSharedFilterImage\0")
                    .map_err(missing)?,
                set_bool: *library.get(b"oidnSetFilterBool\0").map_err(missing)?,
                commit_filter: *library.get(b"oidnCommitFilter\0").map_err(missing)?,
                execute_filter: *library.get(b"oidnExecuteFilter\0").map_err(missing)?,
                release_filter: *library.get(b"oidnReleaseFilter\0").map_err(missing)?,
            }
        };
        Ok(Self {
            api,
            path,
            _library: library,
        })
    }

    /// Where the library was loaded from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Denoises `image` with the albedo and normal planes of `planes` as
    /// guides, handed over as `guides` says.
    ///
    /// # Panics
    ///
    /// If `planes` is not the size of `image`.
    pub fn denoise(
        &self,
        image: &Image,
        planes: &AovImage,
        guides: Guides,
    ) -> Result<Image, DenoiseError> {
        assert_eq!((image.width, image.height), (planes.width, planes.height));
        let (w, h) = (image.width as usize, image.height as usize);
        let flat = |v: &[Rgb]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<f32>>();
        let mut color = flat(&image.pixels);
        let mut albedo = flat(&planes.albedo);
        let mut normal = flat(&planes.normal);
        let mut output = vec![0.0f32; color.len()];
        let device = Device::new(&self.api)?;
        if guides == Guides::Prefilter {
            for (name, plane) in [("albedo", &mut albedo), ("normal", &mut normal)] {
                let mut clean = vec![0.0f32; plane.len()];
                device.run(
                    &mut [(name, &mut *plane), ("output", &mut clean)],
                    (w, h),
                    &[],
                )?;
                *plane = clean;
            }
        }
        device.run(
            &mut [
                ("color", &mut color),
                ("albedo", &mut albedo),
                ("normal", &mut normal),
                ("output", &mut output),
            ],
            (w, h),
            &[("hdr", true), ("cleanAux", true)],
        )?;
        Ok(Image {
            width: image.width,
            height: image.height,
            pixels: output
                .chunks_exact(3)
                .map(|c| Rgb::new(c[0], c[1], c[2]))
                .collect(),
        })
    }
}

/// An OIDN CPU device, released when dropped.
struct Device<'a> {
    api: &'a Api,
    handle: Handle,
}

impl<'a> Device<'a> {
    fn new(api: &'a Api) -> Result<Self, DenoiseError> {
        // SAFETY: plain calls of the C API with valid arguments; a null
        // handle is reported by `check`.
        let handle = unsafe { (api.new_device)(DEVICE_CPU) };
        if handle.is_null() {
            return Err(DenoiseError::Failed("it has no CPU device".into()));
        }
        let device = Self { api, handle };
        // SAFETY: `handle` is a live device.
        unsafe { (api.commit_device)(handle) };
        device.check()?;
        Ok(device)
    }

    /// The device's pending error, if any.
    fn check(&self) -> Result<(), DenoiseError> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: `handle` is a live device; OIDN sets `message` to a
        // NUL-terminated string it owns (or leaves it null).
        let code = unsafe { (self.api.device_error)(self.handle, &mut message) };
        if code == 0 {
            return Ok(());
        }
        let text = if message.is_null() {
            format!("error code {code}")
        } else {
            // SAFETY: see above; copied before the next call.
            unsafe { CStr::from_ptr(message) }
                .to_string_lossy()
                .into_owned()
        };
        Err(DenoiseError::Failed(text))
    }

    /// Runs an `RT` filter over `images` (name, `w × h` float RGB planes)
    /// with the boolean parameters `flags`.
    fn run(
        &self,
        images: &mut [(&str, &mut Vec<f32>)],
        (w, h): (usize, usize),
        flags: &[(&str, bool)],
    ) -> Result<(), DenoiseError> {
        let name = |s: &str| CString::new(s).expect("parameter names have no NUL");
        // SAFETY: `handle` is a live device and the type a C string.
        let filter = unsafe { (self.api.new_filter)(self.handle, name("RT").as_ptr()) };
        self.check()?;
        let result = (|| {
            for (image, data) in images.iter_mut() {
                assert_eq!(data.len(), w * h * 3);
                // SAFETY: `data` holds w·h packed float RGB pixels and
                // outlives the filter's execution below; strides 0 mean
                // packed.
                unsafe {
                    (self.api.set_image)(
                        filter,
                        name(image).as_ptr(),
                        data.as_mut_ptr().cast::<c_void>(),
                        FORMAT_FLOAT3,
                        w,
                        h,
                        0,
                        0,
                        0,
                    )
                };
            }
            for &(flag, value) in flags {
                // SAFETY: a live filter and a C string.
                unsafe { (self.api.set_bool)(filter, name(flag).as_ptr(), value) };
            }
            // SAFETY: a live filter whose images are set.
            unsafe { (self.api.commit_filter)(filter) };
            self.check()?;
            // SAFETY: as above; the call returns when the output is written.
            unsafe { (self.api.execute_filter)(filter) };
            self.check()
        })();
        // SAFETY: the filter is released once, after its last use.
        unsafe { (self.api.release_filter)(filter) };
        result
    }
}

impl Drop for Device<'_> {
    fn drop(&mut self) {
        // SAFETY: the device is released once, after its filters.
        unsafe { (self.api.release_device)(self.handle) };
    }
}
