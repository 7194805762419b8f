/* The C API from plain C99 (compiled -std=c99 -pedantic -Werror by tests/c_host.rs): bad input
 * gets a clear code and message and crashes nothing. No device is needed for these calls. */
#include "shine.h"

#include <stdio.h>
#include <string.h>

static int failures = 0;

/* Checks that `got` is `want` and that the message mentions `needle`. */
static void expect(const char *what, ShineResult got, ShineResult want, const char *needle) {
    const char *message = shine_last_error();
    int ok = got == want && message != NULL && strstr(message, needle) != NULL;
    printf("%s %s: code %d, \"%s\"\n", ok ? "ok  " : "FAIL", what, (int)got, message ? message : "(null)");
    if (!ok) {
        failures++;
    }
}

int main(void) {
    ShineScene_T *scene = NULL;
    ShineScene_T *gone = NULL;
    ShineGeometry geometry;
    float view[16], projection[16];
    ShineContextDesc desc;
    ShineContext_T *context = NULL;

    expect("null scene handle", shine_scene_flatten(NULL, 0.0f, &geometry),
           SHINE_RESULT_ERROR_NULL_HANDLE, "null");
    expect("missing file", shine_scene_load("/nonexistent/scene.glb", &scene),
           SHINE_RESULT_ERROR_SCENE, "/nonexistent/scene.glb");
    if (scene != NULL) {
        printf("FAIL a failed load wrote a handle\n");
        failures++;
    }
    expect("unknown built-in", shine_scene_load("builtin:no-such-scene", &scene),
           SHINE_RESULT_ERROR_SCENE, "no-such-scene");
    expect("null path", shine_scene_load(NULL, &scene), SHINE_RESULT_ERROR_INVALID_ARGUMENT,
           "path");

    expect("load", shine_scene_load("builtin:cornell-box", &scene), SHINE_RESULT_SUCCESS, "");
    expect("flatten", shine_scene_flatten(scene, 0.0f, &geometry), SHINE_RESULT_SUCCESS, "");
    if (geometry.vertex_count == 0 || geometry.index_count % 3 != 0 || geometry.draw_count == 0) {
        printf("FAIL geometry: %u vertices, %u indices, %u draws\n", geometry.vertex_count,
               geometry.index_count, geometry.draw_count);
        failures++;
    }
    expect("NaN time", shine_scene_flatten(scene, 0.0f / 0.0f, &geometry),
           SHINE_RESULT_ERROR_INVALID_ARGUMENT, "finite");
    expect("camera", shine_scene_camera(scene, 0, 0.0f, 64, 64, view, projection),
           SHINE_RESULT_SUCCESS, "");
    expect("camera out of range", shine_scene_camera(scene, 99, 0.0f, 64, 64, view, projection),
           SHINE_RESULT_ERROR_INVALID_ARGUMENT, "camera 99");

    /* A scene handle is not a context, and a device call with a scene handle is refused. */
    expect("wrong kind", shine_context_reset_history((ShineContext_T *)scene),
           SHINE_RESULT_ERROR_STALE_HANDLE, "names a scene");
    memset(&desc, 0, sizeof desc);
    desc.version = SHINE_CONTEXT_DESC_VERSION;
    desc.width = 64;
    desc.height = 64;
    desc.technique = "hvl";
    expect("context on a scene handle",
           shine_context_create((ShineDevice_T *)scene, &desc, &context),
           SHINE_RESULT_ERROR_STALE_HANDLE, "device");

    /* Destroyed: every later use is refused, a second destroy too. */
    gone = scene;
    expect("destroy", shine_scene_destroy(scene), SHINE_RESULT_SUCCESS, "");
    expect("use after destroy", shine_scene_flatten(gone, 0.0f, &geometry),
           SHINE_RESULT_ERROR_STALE_HANDLE, "destroyed");
    expect("double destroy", shine_scene_destroy(gone), SHINE_RESULT_ERROR_STALE_HANDLE,
           "destroyed");
    expect("never made", shine_context_destroy((ShineContext_T *)(uintptr_t)0x7fffffff),
           SHINE_RESULT_ERROR_STALE_HANDLE, "never made");
    expect("null device desc", shine_device_create(NULL, NULL), SHINE_RESULT_ERROR_INVALID_ARGUMENT,
           "null");
    expect("null context", shine_context_dispatch(NULL, NULL, NULL), SHINE_RESULT_ERROR_NULL_HANDLE,
           "null");
    expect("resize a null context", shine_context_resize(NULL, 64, 64),
           SHINE_RESULT_ERROR_NULL_HANDLE, "null");
    expect("memory of a destroyed scene", shine_context_memory_report((ShineContext)gone, NULL),
           SHINE_RESULT_ERROR_STALE_HANDLE, "destroyed");

    printf("%d failure(s)\n", failures);
    return failures == 0 ? 0 : 1;
}
