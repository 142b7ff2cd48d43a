// cv_adapter.cpp: the one file of the classifier that includes OpenCV.
// Every exported function is an exception firewall (STYLE.md): no exception
// and no C++ type leaves this file.
#include "cv_adapter.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

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

extern "C" sp_result sp_cv_draw_polylines(const float* xy, const int* counts, int polylines, int size, int thickness,
                                          unsigned char* out, sp_error* err)
{
    try {
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

extern "C" sp_result sp_cv_decode_grey(const unsigned char* bytes, size_t len, const char* name, unsigned char** pixels, int* w,
                                       int* h, sp_error* err)
{
    *pixels = nullptr;
    try {
        cv::Mat buf(1, (int)len, CV_8UC1, const_cast<unsigned char*>(bytes));
        cv::Mat img = cv::imdecode(buf, cv::IMREAD_UNCHANGED);
        if (img.empty()) return sp_fail(err, SP_ERR_PARSE, "%s: not a decodable image", name);
        if (img.depth() != CV_8U) {
            cv::Mat tmp;
            double s = img.depth() == CV_16U ? 1.0 / 257.0 : 1.0;
            img.convertTo(tmp, CV_8U, s);
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
            cv::cvtColor(rgb, g, cv::COLOR_BGR2GRAY);
            cv::Mat gf, af;
            g.convertTo(gf, CV_32F);
            ch[3].convertTo(af, CV_32F, 1.0 / 255.0);
            cv::Mat outf = gf.mul(af) + (1.0 - af) * 255.0;
            outf.convertTo(grey, CV_8U);
        } else if (img.channels() == 3) {
            cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
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
        *w = grey.cols;
        *h = grey.rows;
        return SP_OK;
    }
    SP_CV_FIREWALL(err, name)
}

extern "C" sp_result sp_cv_fit_raster(const unsigned char* grey, int w, int h, int size, int pad, int fit, unsigned char* out,
                                      sp_error* err)
{
    try {
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
        cv::Mat src(size, size, CV_8UC1, const_cast<unsigned char*>(img));
        // Why thread_local: these few MB are needed for every drawing; reusing them
        // avoids fresh (page-faulting) allocations that cost as much as the maths.
        thread_local cv::Mat gx, gy, bins[4], small;
        cv::Sobel(src, gx, CV_32F, 1, 0, 3, 1.0 / 255.0);
        cv::Sobel(src, gy, CV_32F, 0, 1, 3, 1.0 / 255.0);
        for (int b = 0; b < 4; ++b) {
            bins[b].create(size, size, CV_32F);
            bins[b].setTo(0);
        }
        const float kBin = (float)(4.0 / M_PI);
        for (int y = 0; y < size; ++y) {
            const float* px = gx.ptr<float>(y);
            const float* py = gy.ptr<float>(y);
            float* o[4] = {bins[0].ptr<float>(y), bins[1].ptr<float>(y), bins[2].ptr<float>(y), bins[3].ptr<float>(y)};
            for (int x = 0; x < size; ++x) {
                float dx = px[x], dy = py[x];
                float m = std::sqrt(dx * dx + dy * dy);
                if (m < 1e-6f) continue;
                float a = std::atan2(dy, dx);
                if (a < 0.0f) a += (float)M_PI; // unsigned orientation in [0, pi]
                float f = a * kBin;
                int b0 = (int)f;
                float t = f - (float)b0;
                b0 &= 3;
                o[b0][x] += m * (1.0f - t);
                o[(b0 + 1) & 3][x] += m * t;
            }
        }
        int osz = size / down;
        for (int b = 0; b < 4; ++b) {
            cv::Mat dst(osz, osz, CV_32F, maps + (size_t)b * osz * osz);
            const cv::Mat* from = &bins[b];
            if (down > 1) {
                cv::resize(bins[b], small, cv::Size(osz, osz), 0, 0, cv::INTER_AREA);
                from = &small;
            }
            if (sigma > 0.0)
                cv::GaussianBlur(*from, dst, cv::Size(0, 0), sigma, sigma, cv::BORDER_CONSTANT);
            else
                from->copyTo(dst);
        }
        return SP_OK;
    }
    SP_CV_FIREWALL(err, "orientation")
}

extern "C" sp_result sp_cv_dot_rows(const float* a, int n, const float* b, int k, int dim, float* out, sp_error* err)
{
    try {
        // Why one OpenCV thread: the classifier already runs one job per
        // drawing on each of its own threads; OpenCV's pool on top of that only
        // oversubscribed the cores (a third of training time went to the kernel).
        static std::once_flag once;
        std::call_once(once, [] { cv::setNumThreads(1); });
        const cv::Mat A(n, dim, CV_32F, const_cast<float*>(a));
        const cv::Mat B(k, dim, CV_32F, const_cast<float*>(b));
        cv::Mat C(n, k, CV_32F, out); // written in place: gemm keeps a destination of the right size and type
        cv::gemm(A, B, 1.0, cv::noArray(), 0.0, C, cv::GEMM_2_T);
        if (C.data != reinterpret_cast<unsigned char*>(out)) return sp_fail(err, SP_ERR_INTERNAL, "dot products: OpenCV reallocated the output");
        return SP_OK;
    }
    SP_CV_FIREWALL(err, "dot products")
}
