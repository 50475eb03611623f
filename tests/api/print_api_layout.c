/* Prints the size of each structure of the public header and the offset of
 * each of its fields, one a line ("PtrRenderOptions 176", "PtrRenderOptions
 * samples 8"), for the Python module's test that its ctypes copies agree
 * (python/tests/test_ptr.py, test_structures_agree_with_header). */
#include <stddef.h>
#include <stdio.h>

#include "ptr/ptr.h"

#define SIZE(type) printf("%s %zu\n", #type, sizeof(type))
#define FIELD(type, field) printf("%s %s %zu\n", #type, #field, offsetof(type, field))

int main(void)
{
    SIZE(PtrErrorInfo);
    FIELD(PtrErrorInfo, code);
    FIELD(PtrErrorInfo, message);
    SIZE(PtrContextOptions);
    FIELD(PtrContextOptions, threads);
    FIELD(PtrContextOptions, cpu_cap);
    FIELD(PtrContextOptions, weights_dir);
    FIELD(PtrContextOptions, ocio_config);
    SIZE(PtrCameraDesc);
    FIELD(PtrCameraDesc, lookfrom);
    FIELD(PtrCameraDesc, lookat);
    FIELD(PtrCameraDesc, up);
    FIELD(PtrCameraDesc, vfov_deg);
    FIELD(PtrCameraDesc, ortho_height);
    FIELD(PtrCameraDesc, aperture);
    FIELD(PtrCameraDesc, focus_distance);
    SIZE(PtrLoadOptions);
    FIELD(PtrLoadOptions, camera_name);
    FIELD(PtrLoadOptions, camera);
    FIELD(PtrLoadOptions, orthographic);
    FIELD(PtrLoadOptions, fit_all_objects);
    FIELD(PtrLoadOptions, select);
    FIELD(PtrLoadOptions, drop_hydrogens);
    FIELD(PtrLoadOptions, assembly);
    FIELD(PtrLoadOptions, model);
    FIELD(PtrLoadOptions, orbit_degrees);
    FIELD(PtrLoadOptions, width);
    FIELD(PtrLoadOptions, height);
    FIELD(PtrLoadOptions, sky);
    FIELD(PtrLoadOptions, color_by);
    FIELD(PtrLoadOptions, colormap);
    FIELD(PtrLoadOptions, color_range);
    SIZE(PtrMaterialDesc);
    FIELD(PtrMaterialDesc, type);
    FIELD(PtrMaterialDesc, albedo);
    FIELD(PtrMaterialDesc, fuzz);
    FIELD(PtrMaterialDesc, ior);
    FIELD(PtrMaterialDesc, emission);
    SIZE(PtrSceneArrays);
    FIELD(PtrSceneArrays, count);
    FIELD(PtrSceneArrays, centers);
    FIELD(PtrSceneArrays, centers_f64);
    FIELD(PtrSceneArrays, radii);
    FIELD(PtrSceneArrays, material_indices);
    FIELD(PtrSceneArrays, colors);
    FIELD(PtrSceneArrays, materials);
    FIELD(PtrSceneArrays, material_count);
    FIELD(PtrSceneArrays, camera);
    FIELD(PtrSceneArrays, orthographic);
    FIELD(PtrSceneArrays, width);
    FIELD(PtrSceneArrays, height);
    FIELD(PtrSceneArrays, sky);
    SIZE(PtrRenderOptions);
    FIELD(PtrRenderOptions, width);
    FIELD(PtrRenderOptions, height);
    FIELD(PtrRenderOptions, samples);
    FIELD(PtrRenderOptions, first_sample);
    FIELD(PtrRenderOptions, seed);
    FIELD(PtrRenderOptions, max_depth);
    FIELD(PtrRenderOptions, threads);
    FIELD(PtrRenderOptions, integrator);
    FIELD(PtrRenderOptions, kernel);
    FIELD(PtrRenderOptions, cpu_cap);
    FIELD(PtrRenderOptions, accel);
    FIELD(PtrRenderOptions, sampler);
    FIELD(PtrRenderOptions, direct_lighting);
    FIELD(PtrRenderOptions, noise_threshold);
    FIELD(PtrRenderOptions, min_samples);
    FIELD(PtrRenderOptions, transparent);
    FIELD(PtrRenderOptions, passes);
    FIELD(PtrRenderOptions, denoise);
    FIELD(PtrRenderOptions, sky);
    FIELD(PtrRenderOptions, camera);
    FIELD(PtrRenderOptions, region);
    FIELD(PtrRenderOptions, time_budget);
    SIZE(PtrProgressInfo);
    FIELD(PtrProgressInfo, samples_done);
    FIELD(PtrProgressInfo, samples_total);
    FIELD(PtrProgressInfo, fraction);
    FIELD(PtrProgressInfo, elapsed);
    SIZE(PtrSaveOptions);
    FIELD(PtrSaveOptions, depth);
    FIELD(PtrSaveOptions, dither);
    FIELD(PtrSaveOptions, display);
    FIELD(PtrSaveOptions, view);
    FIELD(PtrSaveOptions, look);
    FIELD(PtrSaveOptions, exposure);
    FIELD(PtrSaveOptions, bake_view);
    return 0;
}
