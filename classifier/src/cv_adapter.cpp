// cv_adapter.cpp: the one file of the classifier that includes OpenCV.
// Every exported function is an exception firewall (STYLE.md): no exception
// and no C++ type leaves this file.
#include "cv_adapter.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <vector>

#define SP_CV_FIREWALL(err, ctx)                                                                                                 \
    catch (const cv::Exception& e)                                                                                               \
    {                                                                                                                            \
        return sp_fail(err, SP_ERR_INTERNAL, "%s: OpenCV: %s", ctx, e.what());                                                   \
    }                                                                                                                            \
    catch (const std::bad_alloc&)                                                                                                \
    {                                                                                                                            \
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", ctx);                                                         \
    }                                                                                                                            \
    catch (...)                                                                                                                  \
    {                                                                                                                            \
        return sp_fail(err, SP_ERR_INTERNAL, "%s: unexpected exception", ctx);                                                   \
    }

// Why one thread for OpenCV and for the BLAS under it: the classifier already
// runs one job per drawing on each of its own threads, and a single drawing's
// work is small; OpenCV's pool and OpenBLAS's threads on top of that only
// oversubscribed the cores (training time went to the kernel, and on a loaded
// machine OpenBLAS's spinning threads slowed one classification's nearest-word
// products several-fold; BENCHMARKS.md, "Classifier training" and
// "Quick, Draw! 100 categories"). OpenBLAS is looked up at run
// time so that any other BLAS under OpenCV works unchanged. Process-wide: the
// solver's LAPACK calls are on matrices too small to gain from threads.
static void single_threaded()
{
    static std::once_flag once;
    std::call_once(once, [] {
        cv::setNumThreads(1);
        using set_threads_fn = void (*)(int);
        if (void* f = dlsym(RTLD_DEFAULT, "openblas_set_num_threads")) reinterpret_cast<set_threads_fn>(f)(1);
    });
}

extern "C" sp_result sp_cv_draw_polylines(const float* xy, const int* counts, int polylines, int size, int thickness,
                                          unsigned char* out, sp_error* err)
{
    try {
        single_threaded();
        cv::Mat img(size, size, CV_8UC1, out);
        img.setTo(0);
        // Why fixed point with 4 fractional bits: sub-pixel placement keeps the
        // anti-aliasing faithful to the stroke instead of snapping to pixels.
        const int shift = 4;
        const float scale = float(1 << shift);
        std::vector<cv::Point> pts;
        const float* p = xy;
        for (int i = 0; i < polylines; ++i) {
            int n = counts[i];
            pts.resize((size_t)n);
            for (int j = 0; j < n; ++j)
                pts[(size_t)j] = cv::Point((int)std::lround(p[2 * j] * scale), (int)std::lround(p[2 * j + 1] * scale));
            p += 2 * n;
            if (n == 1) {
                cv::circle(img, pts[0], (thickness * (1 << shift)) / 2, cv::Scalar(255), cv::FILLED, cv::LINE_AA, shift);
            } else if (n > 1) {
                const cv::Point* pp = pts.data();
                cv::polylines(img, &pp, &n, 1, false, cv::Scalar(255), thickness, cv::LINE_AA, shift);
            }
        }
        return SP_OK;
    }
    SP_CV_FIREWALL(err, "rasterise")
}

extern "C" sp_result sp_cv_grey(const void* samples, int w, int h, int channels, bool wide, const char* name,
                                unsigned char** pixels, sp_error* err)
{
    *pixels = nullptr;
    try {
        single_threaded();
        if (channels < 1 || channels > 4) return sp_fail(err, SP_ERR_INVALID, "%s: %d channels", name, channels);
        cv::Mat img(h, w, CV_MAKETYPE(wide ? CV_16U : CV_8U, channels), const_cast<void*>(samples));
        if (wide) {
            cv::Mat tmp;
            img.convertTo(tmp, CV_8U, 1.0 / 257.0);
            img = tmp;
        }
        cv::Mat grey;
        if (img.channels() == 4) {
            // Why composite: many sketch PNGs are black lines on a transparent
            // background whose hidden colour is black too.
            std::vector<cv::Mat> ch;
            cv::split(img, ch);
            cv::Mat rgb, g;
            cv::merge(std::vector<cv::Mat>{ch[0], ch[1], ch[2]}, rgb);
            cv::cvtColor(rgb, g, cv::COLOR_RGB2GRAY);
            cv::Mat gf, af;
            g.convertTo(gf, CV_32F);
            ch[3].convertTo(af, CV_32F, 1.0 / 255.0);
            cv::Mat outf = gf.mul(af) + (1.0 - af) * 255.0;
            outf.convertTo(grey, CV_8U);
        } else if (img.channels() == 3) {
            cv::cvtColor(img, grey, cv::COLOR_RGB2GRAY);
        } else if (img.channels() == 2) {
            std::vector<cv::Mat> ch;
            cv::split(img, ch);
            cv::Mat gf, af, outf;
            ch[0].convertTo(gf, CV_32F);
            ch[1].convertTo(af, CV_32F, 1.0 / 255.0);
            outf = gf.mul(af) + (1.0 - af) * 255.0;
            outf.convertTo(grey, CV_8U);
        } else {
            grey = img;
        }
        if (!grey.isContinuous()) grey = grey.clone();
        size_t n = (size_t)grey.rows * (size_t)grey.cols;
        unsigned char* p = (unsigned char*)std::malloc(n ? n : 1);
        if (!p) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
        std::memcpy(p, grey.data, n);
        *pixels = p;
        return SP_OK;
    }
    SP_CV_FIREWALL(err, name)
}

extern "C" sp_result sp_cv_fit_raster(const unsigned char* grey, int w, int h, int size, int pad, int fit, unsigned char* out,
                                      sp_error* err)
{
    try {
        single_threaded();
        cv::Mat src(h, w, CV_8UC1, const_cast<unsigned char*>(grey));
        cv::Mat ink = 255 - src; // ink bright
        cv::Mat mask;
        cv::threshold(ink, mask, 64, 255, cv::THRESH_BINARY);
        cv::Rect box = cv::boundingRect(mask);
        cv::Mat dst(size, size, CV_8UC1, out);
        dst.setTo(0);
        if (box.width == 0 || box.height == 0) return sp_fail(err, SP_ERR_INVALID, "raster has no dark lines");
        double s = (double)fit / (double)std::max(box.width, box.height);
        int nw = std::max(1, (int)std::lround(box.width * s)), nh = std::max(1, (int)std::lround(box.height * s));
        cv::Mat crop = ink(box), scaled;
        cv::resize(crop, scaled, cv::Size(nw, nh), 0, 0, s < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
        // Why: thin lines shrunk a lot fade to grey; restore their contrast so
        // PNG sketches look like rasterised strokes.
        double mx = 0.0;
        cv::minMaxLoc(scaled, nullptr, &mx);
        if (mx > 0.0 && mx < 255.0) scaled.convertTo(scaled, CV_8U, 255.0 / mx);
        int x0 = pad + (fit - nw) / 2, y0 = pad + (fit - nh) / 2;
        scaled.copyTo(dst(cv::Rect(x0, y0, nw, nh)));
        return SP_OK;
    }
    SP_CV_FIREWALL(err, "raster")
}

extern "C" sp_result sp_cv_orientation_maps(const unsigned char* img, int size, int down, double sigma, float* maps,
                                            sp_error* err)
{
    try {
        single_threaded();
        if (down != 1 && down != 2) return sp_fail(err, SP_ERR_INVALID, "orientation: downsampling %d is not 1 or 2", down);
        // Why one fused pass instead of Sobel, four full-size planes and four
        // resizes: the same 3x3 Sobel gradient, split into the bins and averaged
        // over down x down blocks (what INTER_AREA does for an integer factor)
        // straight into the small planes; rows without ink nearby are skipped.
        // The planes were a large share of a classification's descriptors
        // (BENCHMARKS.md, "Quick, Draw! 100 categories").
        const int osz = size / down;
        const float w = 1.0f / (255.0f * (float)(down * down));
        thread_local std::vector<float> small;
        thread_local std::vector<unsigned char> ink;
        small.assign((size_t)4 * osz * osz, 0.0f);
        ink.assign((size_t)size, 0);
        for (int y = 0; y < size; ++y) {
            const unsigned char* r = img + (size_t)y * size;
            for (int x = 0; x < size && !ink[(size_t)y]; ++x)
                ink[(size_t)y] = r[x] != 0;
        }
        const float kBin = (float)(4.0 / M_PI);
        // The outermost rows and columns keep a zero gradient (cv::Sobel would
        // reflect there; sketches never come near the canvas border).
        for (int y = 1; y < size - 1 && y / down < osz; ++y) {
            if (!ink[(size_t)y - 1] && !ink[(size_t)y] && !ink[(size_t)y + 1]) continue;
            const unsigned char* r0 = img + (size_t)(y - 1) * size;
            const unsigned char* r1 = r0 + size;
            const unsigned char* r2 = r1 + size;
            float* o[4];
            for (int b = 0; b < 4; ++b)
                o[b] = small.data() + (size_t)b * osz * osz + (size_t)(y / down) * osz;
            for (int x = 1; x < size - 1 && x / down < osz; ++x) {
                int gx = (r0[x + 1] + 2 * r1[x + 1] + r2[x + 1]) - (r0[x - 1] + 2 * r1[x - 1] + r2[x - 1]);
                int gy = (r2[x - 1] + 2 * r2[x] + r2[x + 1]) - (r0[x - 1] + 2 * r0[x] + r0[x + 1]);
                if (gx == 0 && gy == 0) continue;
                float dx = (float)gx, dy = (float)gy;
                float m = std::sqrt(dx * dx + dy * dy) * w;
                float a = std::atan2(dy, dx);
                if (a < 0.0f) a += (float)M_PI; // unsigned orientation in [0, pi]
                float f = a * kBin;
                int b0 = (int)f;
                float t = f - (float)b0;
                b0 &= 3;
                o[b0][x / down] += m * (1.0f - t);
                o[(b0 + 1) & 3][x / down] += m * t;
            }
        }
        for (int b = 0; b < 4; ++b) {
            cv::Mat src(osz, osz, CV_32F, small.data() + (size_t)b * osz * osz);
            cv::Mat dst(osz, osz, CV_32F, maps + (size_t)b * osz * osz);
            if (sigma > 0.0)
                cv::GaussianBlur(src, dst, cv::Size(0, 0), sigma, sigma, cv::BORDER_CONSTANT);
            else
                src.copyTo(dst);
        }
        return SP_OK;
    }
    SP_CV_FIREWALL(err, "orientation")
}

extern "C" sp_result sp_cv_blur_halve(const float* planes, int count, int size, double sigma, float* out, sp_error* err)
{
    try {
        single_threaded();
        const int half = size / 2, k = 2 * (int)std::lround(4.0 * sigma) + 1;
        for (int i = 0; i < count; ++i) {
            cv::Mat src(size, size, CV_32FC1, const_cast<float*>(planes) + (size_t)i * size * size), blurred;
            cv::Mat dst(half, half, CV_32FC1, out + (size_t)i * half * half);
            cv::GaussianBlur(src, blurred, cv::Size(k, k), sigma, sigma, cv::BORDER_REFLECT);
            cv::resize(blurred, dst, dst.size(), 0, 0, cv::INTER_AREA);
        }
        return SP_OK;
    }
    SP_CV_FIREWALL(err, "picture")
}

extern "C" sp_result sp_cv_dot_rows(const float* a, int n, const float* b, int k, int dim, float* out, sp_error* err)
{
    try {
        single_threaded();
        const cv::Mat A(n, dim, CV_32F, const_cast<float*>(a));
        const cv::Mat B(k, dim, CV_32F, const_cast<float*>(b));
        cv::Mat C(n, k, CV_32F, out); // written in place: gemm keeps a destination of the right size and type
        cv::gemm(A, B, 1.0, cv::noArray(), 0.0, C, cv::GEMM_2_T);
        if (C.data != reinterpret_cast<unsigned char*>(out)) return sp_fail(err, SP_ERR_INTERNAL, "dot products: OpenCV reallocated the output");
        return SP_OK;
    }
    SP_CV_FIREWALL(err, "dot products")
}

extern "C" sp_result sp_cv_convexity(const int* xy, int n, double* area, double* hull_area, sp_cv_defect* defects, int max,
                                     int* count, sp_error* err)
{
    *count = 0;
    *area = *hull_area = 0.0;
    try {
        single_threaded();
        if (n < 4) return sp_fail(err, SP_ERR_INVALID, "convexity: %d points (4 needed)", n);
        std::vector<cv::Point> pts((size_t)n);
        for (int i = 0; i < n; ++i)
            pts[(size_t)i] = cv::Point(xy[2 * i], xy[2 * i + 1]);
        *area = std::fabs(cv::contourArea(pts));
        std::vector<int> idx;
        cv::convexHull(pts, idx, false, false);
        std::vector<cv::Point> hull;
        for (int i : idx)
            hull.push_back(pts[(size_t)i]);
        *hull_area = hull.size() >= 3 ? cv::contourArea(hull) : 0.0;
        // Why sorted: a drawn stroke may cross itself, and convexityDefects
        // refuses hull indices that are not monotonous along the polygon; in
        // polygon order every hull edge spans the run of points it covers.
        std::sort(idx.begin(), idx.end());
        if (idx.size() < 3) return SP_OK;
        std::vector<cv::Vec4i> d;
        cv::convexityDefects(pts, idx, d);
        for (const cv::Vec4i& v : d) {
            if (*count >= max) break;
            defects[(*count)++] = sp_cv_defect{v[0], v[1], v[2], (float)v[3] / 256.0f};
        }
        return SP_OK;
    }
    SP_CV_FIREWALL(err, "convexity")
}
