// The scene header at the start of module_params (modules.rs): where
// each table is, and the counts.
const H_ROOT: u32 = 0u;
const H_CAMERA: u32 = 1u;
const H_SAMPLER: u32 = 2u;
const H_FILTER: u32 = 3u;
const H_FILTER_RES: u32 = 4u;
const H_FILTER_RADIUS: u32 = 5u;
const H_FILTER_INTEGRAL: u32 = 6u;
const H_MATERIALS: u32 = 7u;
const H_TEXTURES: u32 = 8u;
const H_LIGHTS: u32 = 9u;
const H_LIGHT_COUNT: u32 = 10u;
const H_LIGHT_CDF: u32 = 11u;
const H_ENVIRONMENT: u32 = 12u;
const H_ENVIRONMENT_COUNT: u32 = 13u;
const H_SPLAT: u32 = 14u;
const H_SPLAT_SCALE: u32 = 15u;
const H_SPLAT_REACH: u32 = 16u;
const H_CAMERA_MOTION: u32 = 17u;
const H_LIGHT_SELECTION: u32 = 18u;
