//! The demo scene (`Scene::DEMO`) prepared at build time: the build script prepares it
//! on the host with `misalign` (a build-dependency) and writes each scene type's bytes
//! (`misalign::prepared`'s format) here, with the fixed-point LSBs of the images. An
//! image loads them with `from_bytes` (integer checks only), so that it links no f64
//! preparation and no libm, and answers bit for bit as preparing on the node.

include!(concat!(env!("OUT_DIR"), "/prepared.rs"));
