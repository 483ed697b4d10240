/* Batch driver for engine/benches/embree_peer.py: builds an Embree 4 scene
 * over a triangle soup and traces whole arrays of rays with rtcIntersect1 /
 * rtcOccluded1 in a C loop, so that no per-ray cost of a Python binding is
 * counted. Declares the few Embree 4 entry points it needs itself (the
 * wheel of `embreex` ships the library, not its headers). */
#include <stddef.h>
#include <string.h>

typedef void *RTCDevice, *RTCScene, *RTCGeometry;
RTCDevice rtcNewDevice(const char *config);
RTCScene rtcNewScene(RTCDevice device);
RTCGeometry rtcNewGeometry(RTCDevice device, int type);
void *rtcSetNewGeometryBuffer(RTCGeometry g, int type, unsigned slot, int format,
                              size_t stride, size_t count);
void rtcCommitGeometry(RTCGeometry g);
unsigned rtcAttachGeometry(RTCScene s, RTCGeometry g);
void rtcReleaseGeometry(RTCGeometry g);
void rtcCommitScene(RTCScene s);
void rtcSetSceneFlags(RTCScene s, int flags);
void rtcSetSceneBuildQuality(RTCScene s, int quality);
void rtcReleaseScene(RTCScene s);
void rtcReleaseDevice(RTCDevice d);

typedef struct __attribute__((aligned(16))) {
    float org_x, org_y, org_z, tnear, dir_x, dir_y, dir_z, time, tfar;
    unsigned mask, id, flags;
} RTCRay;
typedef struct __attribute__((aligned(16))) {
    float ng_x, ng_y, ng_z, u, v;
    unsigned prim, geom, inst[1];
    unsigned spare[8]; /* room for fields of other configurations */
} RTCHit;
typedef struct __attribute__((aligned(16))) { RTCRay ray; RTCHit hit; } RTCRayHit;
void rtcIntersect1(RTCScene s, RTCRayHit *rh, void *args);
void rtcOccluded1(RTCScene s, RTCRay *r, void *args);

enum { GEOMETRY_TRIANGLE = 0, BUFFER_INDEX = 0, BUFFER_VERTEX = 1,
       FORMAT_UINT3 = 0x5003, FORMAT_FLOAT3 = 0x9003 };
#define INVALID 0xffffffffu

static RTCDevice device;

/* A committed scene over `n` triangles `v` (n·9 floats), or NULL; `flags`
 * are RTCSceneFlags (RTC_SCENE_FLAG_ROBUST = 4), `quality` an
 * RTCBuildQuality (0 low, 1 medium, Embree's default, 2 high). */
RTCScene peer_scene(const float *v, size_t n, int flags, int quality) {
    if (!device) device = rtcNewDevice("threads=1");
    if (!device) return NULL;
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, flags);
    rtcSetSceneBuildQuality(scene, quality);
    RTCGeometry g = rtcNewGeometry(device, GEOMETRY_TRIANGLE);
    float *vb = rtcSetNewGeometryBuffer(g, BUFFER_VERTEX, 0, FORMAT_FLOAT3, 12, 3 * n);
    unsigned *ib = rtcSetNewGeometryBuffer(g, BUFFER_INDEX, 0, FORMAT_UINT3, 12, n);
    memcpy(vb, v, n * 9 * sizeof(float));
    for (size_t i = 0; i < 3 * n; i++) ib[i] = (unsigned)i;
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    return scene;
}

void peer_release(RTCScene s) { rtcReleaseScene(s); }

static void ray_at(RTCRay *r, const float *o, const float *d, size_t i, float tfar) {
    r->org_x = o[3 * i]; r->org_y = o[3 * i + 1]; r->org_z = o[3 * i + 2];
    r->dir_x = d[3 * i]; r->dir_y = d[3 * i + 1]; r->dir_z = d[3 * i + 2];
    r->tnear = 0.0f; r->time = 0.0f; r->tfar = tfar;
    r->mask = INVALID; r->id = 0; r->flags = 0;
}

/* Closest hits: hit[i] the primitive (-1 for a miss), t[i] its distance. */
void peer_intersect(RTCScene s, const float *o, const float *d, size_t n, int *hit, float *t) {
    RTCRayHit rh;
    for (size_t i = 0; i < n; i++) {
        ray_at(&rh.ray, o, d, i, __builtin_inff());
        rh.hit.geom = INVALID;
        rh.hit.prim = INVALID;
        rtcIntersect1(s, &rh, NULL);
        hit[i] = rh.hit.geom == INVALID ? -1 : (int)rh.hit.prim;
        t[i] = rh.ray.tfar;
    }
}

/* Shadow rays to distance tfar[i]: blocked[i] is 1 where something is hit. */
void peer_occluded(RTCScene s, const float *o, const float *d, const float *tfar, size_t n,
                   unsigned char *blocked) {
    RTCRay r;
    for (size_t i = 0; i < n; i++) {
        ray_at(&r, o, d, i, tfar[i]);
        rtcOccluded1(s, &r, NULL);
        /* Embree sets tfar to -inf where the ray is occluded. */
        blocked[i] = r.tfar < 0.0f;
    }
}
