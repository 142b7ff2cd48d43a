// camera.c: orthographic and perspective projection to pixels (y down),
// their 2x3 Jacobians and viewing directions.
#include "sp/rig.h"

sp_vec2 sp_camera_project(const sp_camera* cam, sp_vec3 world)
{
    sp_vec3 c = sp_mat4_point(&cam->view, world);
    if (cam->kind == SP_CAMERA_ORTHOGRAPHIC) return (sp_vec2){cam->cx + cam->scale * c.x, cam->cy - cam->scale * c.y};
    // Why the clamp: a point behind the camera must not produce Inf/NaN that
    // would poison a solve; it lands far away instead.
    double d = -c.z;
    if (d < 1e-9) d = 1e-9;
    return (sp_vec2){cam->cx + cam->scale * c.x / d, cam->cy - cam->scale * c.y / d};
}

void sp_camera_jacobian(const sp_camera* cam, sp_vec3 world, double J[6])
{
    const double* v = cam->view.m;
    // Rows of the view's linear part: d(camera coords)/d(world).
    double r0[3] = {v[0], v[4], v[8]}, r1[3] = {v[1], v[5], v[9]}, r2[3] = {v[2], v[6], v[10]};
    if (cam->kind == SP_CAMERA_ORTHOGRAPHIC) {
        for (int i = 0; i < 3; ++i) {
            J[i] = cam->scale * r0[i];
            J[3 + i] = -cam->scale * r1[i];
        }
        return;
    }
    sp_vec3 c = sp_mat4_point(&cam->view, world);
    double d = -c.z;
    if (d < 1e-9) d = 1e-9;
    double f = cam->scale;
    // u = cx + f x / d, v = cy - f y / d, d = -z: du/dz = f x / d^2.
    double dux = f / d, duz = f * c.x / (d * d);
    double dvy = -f / d, dvz = -f * c.y / (d * d);
    for (int i = 0; i < 3; ++i) {
        J[i] = dux * r0[i] + duz * r2[i];
        J[3 + i] = dvy * r1[i] + dvz * r2[i];
    }
}

sp_vec3 sp_camera_view_dir(const sp_camera* cam, sp_vec3 world)
{
    sp_mat4 inv;
    sp_mat4_inverse(&cam->view, &inv);
    if (cam->kind == SP_CAMERA_ORTHOGRAPHIC) return sp_v3_norm(sp_mat4_dir(&inv, (sp_vec3){0, 0, -1}));
    return sp_v3_norm(sp_v3_sub(world, sp_mat4_translation(&inv)));
}

sp_camera sp_camera_default_view(const double* xyz, int n, int width, int height)
{
    sp_vec3 lo, hi;
    sp_bounds(xyz, n, &lo, &hi);
    double mx = 0, mz = 0, vx = 0, vz = 0;
    for (int i = 0; i < n; ++i) mx += xyz[3 * i], mz += xyz[3 * i + 2];
    if (n > 0) mx /= n, mz /= n;
    for (int i = 0; i < n; ++i) {
        double dx = xyz[3 * i] - mx, dz = xyz[3 * i + 2] - mz;
        vx += dx * dx, vz += dz * dz;
    }
    sp_vec3 forward = vx >= vz ? sp_v3(0, 0, -1) : sp_v3(-1, 0, 0);
    return sp_camera_frame(SP_CAMERA_ORTHOGRAPHIC, lo, hi, forward, sp_v3(0, 1, 0), width, height);
}

sp_camera sp_camera_resize(const sp_camera* cam, int width, int height)
{
    sp_camera c = *cam;
    if (cam->width <= 0 || cam->height <= 0 || width <= 0 || height <= 0) return c;
    double f = fmin((double)width / cam->width, (double)height / cam->height);
    c.scale = cam->scale * f;
    c.cx = 0.5 * width + (cam->cx - 0.5 * cam->width) * f;
    c.cy = 0.5 * height + (cam->cy - 0.5 * cam->height) * f;
    c.width = width;
    c.height = height;
    return c;
}

void sp_bounds(const double* xyz, int n, sp_vec3* lo, sp_vec3* hi)
{
    *lo = (sp_vec3){0, 0, 0};
    *hi = (sp_vec3){0, 0, 0};
    if (n <= 0) return;
    // Comparisons, not fmin / fmax: those are libm calls, and they were a
    // quarter of a dragon export (the bounds of every vertex at every key).
    // A NaN coordinate fails both tests and is passed over, as fmin does.
    double a[3] = {INFINITY, INFINITY, INFINITY}, b[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < 3 * (size_t)n; i += 3)
        for (int c = 0; c < 3; ++c) {
            a[c] = xyz[i + c] < a[c] ? xyz[i + c] : a[c];
            b[c] = xyz[i + c] > b[c] ? xyz[i + c] : b[c];
        }
    for (int c = 0; c < 3; ++c)
        if (a[c] > b[c]) a[c] = b[c] = NAN; // no number at all
    *lo = (sp_vec3){a[0], a[1], a[2]}, *hi = (sp_vec3){b[0], b[1], b[2]};
}

sp_camera sp_camera_frame(sp_camera_kind kind, sp_vec3 lo, sp_vec3 hi, sp_vec3 forward, sp_vec3 up, int width, int height)
{
    sp_camera cam = {0};
    cam.kind = kind;
    cam.width = width;
    cam.height = height;
    cam.cx = 0.5 * width;
    cam.cy = 0.5 * height;
    sp_vec3 zc = sp_v3_norm(sp_v3_scale(forward, -1.0));
    sp_vec3 xc = sp_v3_cross(up, zc);
    if (sp_v3_len(xc) < 1e-9) xc = sp_v3_cross((sp_vec3){1, 0, 0}, zc);
    xc = sp_v3_norm(xc);
    sp_vec3 yc = sp_v3_cross(zc, xc);
    sp_vec3 center = sp_v3_scale(sp_v3_add(lo, hi), 0.5);
    // Extents of the box along the camera axes.
    double ex = 0, ey = 0, ez = 0;
    for (int i = 0; i < 8; ++i) {
        sp_vec3 c = {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
        sp_vec3 d = sp_v3_sub(c, center);
        ex = fmax(ex, fabs(sp_v3_dot(d, xc)));
        ey = fmax(ey, fabs(sp_v3_dot(d, yc)));
        ez = fmax(ez, fabs(sp_v3_dot(d, zc)));
    }
    double radius = sqrt(ex * ex + ey * ey + ez * ez);
    if (!(radius > 1e-9)) radius = 1.0, ex = ey = ez = 1.0;
    ex = fmax(ex, 1e-6 * radius), ey = fmax(ey, 1e-6 * radius);
    const double margin = 1.2; // 10% each side
    double dist;
    if (kind == SP_CAMERA_ORTHOGRAPHIC) {
        cam.scale = fmin(width / (2.0 * ex * margin), height / (2.0 * ey * margin));
        dist = 2.0 * radius + 1.0;
    } else {
        cam.scale = 0.5 * height / tan(0.5 * 40.0 * 3.14159265358979323846 / 180.0); // 40 degree vertical field of view
        dist = ez + fmax(ey * margin * cam.scale / (0.5 * height), ex * margin * cam.scale / (0.5 * width));
    }
    sp_vec3 eye = sp_v3_add(center, sp_v3_scale(zc, dist));
    // view = inverse of the camera's world matrix [xc yc zc eye].
    sp_mat4 v = sp_mat4_identity();
    v.m[0] = xc.x, v.m[4] = xc.y, v.m[8] = xc.z;
    v.m[1] = yc.x, v.m[5] = yc.y, v.m[9] = yc.z;
    v.m[2] = zc.x, v.m[6] = zc.y, v.m[10] = zc.z;
    v.m[12] = -sp_v3_dot(xc, eye), v.m[13] = -sp_v3_dot(yc, eye), v.m[14] = -sp_v3_dot(zc, eye);
    cam.view = v;
    cam.znear = fmax(1e-3 * radius, dist - radius * 1.5);
    cam.zfar = dist + radius * 1.5;
    return cam;
}
