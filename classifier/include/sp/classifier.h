/// sp/classifier.h: which category did someone draw?
///
/// Eitz-style bag of features (Eitz, Hays, Alexa 2012): a drawing is fitted to a
/// 256x256 frame, rasterised, described by 64-D local orientation descriptors on
/// a 28x28 grid, soft-assigned to a k-means vocabulary and summarised as an
/// L1-normalised histogram (optionally with a 1x1+2x2(+4x4) spatial pyramid, tf-idf,
/// and Hellinger-mapped). A k-nearest-neighbour search over the training
/// histograms (full distances for a shortlist of candidates nearest on the
/// whole-drawing level; FLANN's kd-tree beyond 20000 training histograms)
/// votes, weighted by distance, for categories. Optionally (`shape_weight`),
/// global shape evidence the local features lack (open or closed, elongation
/// and axis against the upright canvas, solidity, convexity defects and where
/// they open, turning angles, centroid-distance Fourier magnitudes, where the
/// ink lies) votes too, by its own k nearest training drawings, and so
/// (`picture_weight`, on by default) does a small picture of the whole
/// drawing's line directions; they are fused as a product of their shares
/// into the ranked categories. A drawing farther from every training drawing
/// (histogram distance) than a threshold learned on the training set is
/// rejected.
///
///     sp_dataset ds; sp_dataset_load("data/", &ds, &err);
///     sp_clf* clf; sp_clf_train(&ds, NULL, &(sp_clf_desc){0}, &clf, &err);
///     sp_clf_answer a; sp_clf_classify(clf, &sketch, NULL, &a, &err);
///     printf("%s %.2f\n", sp_clf_category(clf, a.ranked[0].category), a.ranked[0].score);
///     sp_clf_save(clf, "m.spclf", &err); sp_clf_destroy(clf);
///
/// A trained model is immutable: classification may run on several threads at once.
#ifndef SP_CLASSIFIER_H
#define SP_CLASSIFIER_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/result.h"
#include "sp/sketch.h"
#include "sp/sketch_io.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Model file format version written by sp_clf_save; sp_clf_load also reads versions 1
/// (models without shape evidence) and 2 (without picture evidence), and refuses others.
#define SP_CLF_FILE_VERSION 3
/// The picture evidence's weight by default (sp_clf_desc.picture_weight);
/// chosen on the visitors' tune half (tests/data/visitors).
#define SP_CLF_PICTURE_WEIGHT 0.3
/// Most ranked categories in an answer.
#define SP_CLF_MAX_RANKED 10

typedef struct sp_clf sp_clf;

/// Training options. Zero means the default; for switches 1 = on, -1 = off.
typedef struct sp_clf_desc {
    int words;              ///< vocabulary size (default 500)
    int vocab_samples;      ///< descriptors sampled for k-means (default 50000)
    int kmeans_iterations;  ///< Lloyd iterations after k-means++ seeding (default 10)
    int soft_neighbours;    ///< words each descriptor is soft-assigned to (default 4; 1 = hard assignment)
    int knn;                ///< neighbours voting at classification (default 8)
    int pyramid;            ///< spatial pyramid: 1 = 1x1 + 2x2 cells (default), 2 = also 4x4; -1 = whole drawing only
    int tfidf;              ///< tf-idf word weighting (default on: more top-1; BENCHMARKS.md, "Quick, Draw! 100 categories")
    int hellinger;          ///< square-root (Hellinger) map of the histograms before k-NN (default on)
    int mirror;             ///< also train on left-right mirrored drawings (default on)
    int augment;            ///< extra randomly jittered copies of each stroke drawing (default 0; -1 = none)
    double reject_quantile; ///< reject beyond this quantile of training leave-one-out distances (default 0.98)
    uint32_t seed;          ///< every random choice derives from it (default 1)
    int threads;            ///< worker threads (default 2)
    /// Progress report (may be NULL): stage name, done of total.
    void (*progress)(void* user, const char* stage, int done, int total);
    void* progress_user;
    /// Makes augmented copy `k` (0 <= k < augment) of the stroke drawing `in` (dataset sample
    /// `sample`) into `out` (freed by the classifier with sp_sketch_free) instead of the
    /// built-in random affine jitter; may be NULL. E.g. the hand-drawing model
    /// (sp_handdraw_apply, partdb), which the classifier cannot link. Must be deterministic
    /// and thread-safe (called from the training threads). Not stored in the model.
    sp_result (*augment_fn)(void* user, const sp_sketch* in, int sample, int k, sp_sketch* out);
    void* augment_user;
    /// Weight of the global shape evidence (stroke drawings only; rasters are
    /// ranked by the votes): each category's vote share (plus 0.02) times its
    /// shape share raised to this power ranks. 0 (default) or < 0: none, the
    /// votes alone rank. It helps single-stroke drawings of a few categories
    /// (partdb.h's sp_db_train_desc turns it on) and costs accuracy on Quick,
    /// Draw!'s 100 (BENCHMARKS.md, "Visitors' drawings").
    double shape_weight;
    /// Weight of the picture evidence (stroke drawings only; rasters are
    /// ranked without it): the whole drawing as a small picture of where its
    /// line runs which way (after Ouyang and Davis 2009), voted on by the k
    /// nearest training pictures (mirrored ones too); each category's fused
    /// score is multiplied by its picture share (plus 0.02) raised to this
    /// power. 0: SP_CLF_PICTURE_WEIGHT; < 0: none. The bag of features sees
    /// local strokes, the shape descriptor global measures; the picture keeps
    /// the layout (BENCHMARKS.md: Quick, Draw!'s 100 and the visitors' drawings).
    double picture_weight;
} sp_clf_desc;

/// One ranked category: index into the model's categories, and its vote share in [0, 1].
typedef struct sp_clf_rank {
    int category;
    float score;
} sp_clf_rank;

/// A classification: categories by decreasing score (scores sum to <= 1).
typedef struct sp_clf_answer {
    /// ranked entries, at most SP_CLF_MAX_RANKED: the categories that got votes
    /// or, with shape evidence, every category (each has a fused score)
    int count;
    sp_clf_rank ranked[SP_CLF_MAX_RANKED];
    bool rejected;         ///< nothing in the training set is close: ask again
    float distance;        ///< histogram distance to the nearest training drawing
    float reject_distance; ///< the model's threshold for `rejected`
} sp_clf_answer;

/// Trains on the samples of `data` whose `use[i]` is non-zero (`use` NULL: all).
/// Categories are data's categories (those without samples simply never win).
sp_result sp_clf_train(const sp_dataset* data, const unsigned char* use, const sp_clf_desc* desc, sp_clf** out, sp_error* err);
/// Classifies strokes, or (when `sketch` is NULL or empty) a raster. Bad drawings
/// (empty, non-finite, too many points) fail with a one-line message.
sp_result sp_clf_classify(const sp_clf* clf, const sp_sketch* sketch, const sp_raster* raster, sp_clf_answer* out, sp_error* err);
/// Recalibrates the reject threshold on drawings the model was not trained on
/// (held out; `use` NULL: all of `held_out`): the `quantile` (in (0, 1]) of
/// their nearest-neighbour distances, times `margin` (>= 1; 0 means 1).
/// Training sets the threshold from leave-one-out distances among training
/// drawings, which are closer to one another than new drawings are; held-out
/// drawings of the kind the model will see give a threshold that rejects few
/// of them. `distances` (may be NULL) receives the sorted distances, *count of
/// them. Call before sharing the model between threads.
sp_result sp_clf_calibrate_reject(sp_clf* clf, const sp_dataset* held_out, const unsigned char* use, double quantile, double margin,
                                  float* distances, int* count, sp_error* err);
/// The reject threshold (histogram distance; INFINITY: never rejects).
float sp_clf_reject_distance(const sp_clf* clf);
/// Saves with a version header and a checksum, written whole (sp_file_write).
sp_result sp_clf_save(const sp_clf* clf, const char* path, sp_error* err);
/// Loads a model; a corrupt, truncated or other-version file is refused with a clear message.
sp_result sp_clf_load(const char* path, sp_clf** out, sp_error* err);
/// The model file's bytes in memory (*bytes malloc'd, the caller frees), for
/// stores that keep models themselves (the part database).
sp_result sp_clf_to_bytes(const sp_clf* clf, void** bytes, size_t* size, sp_error* err);
/// A model from a model file's bytes; messages begin with `what` (a path, or
/// "DB: model 3").
sp_result sp_clf_from_bytes(const void* bytes, size_t size, const char* what, sp_clf** out, sp_error* err);
/// Frees the model (NULL is fine).
void sp_clf_destroy(sp_clf* clf);

/// Number of categories and the name of one.
int sp_clf_category_count(const sp_clf* clf);
const char* sp_clf_category(const sp_clf* clf, int i);
/// The options the model was trained with, defaults resolved (progress callback NULL).
sp_clf_desc sp_clf_get_desc(const sp_clf* clf);
/// The training-time options with defaults resolved (what a zero field means).
sp_clf_desc sp_clf_desc_defaults(const sp_clf_desc* desc);

/// Reads a PNG into grey pixels (alpha composited over white). Refuses files whose
/// header says more than SP_RASTER_MAX_SIDE a side before decoding anything, and
/// files that are not PNGs whatever their name.
sp_result sp_raster_read_png(const char* path, sp_raster* out, sp_error* err);
/// Reads any single drawing by extension (.json, .svg, .png; .ndjson gives its first drawing).
/// For a PNG, `raster` receives the pixels and `sketch` stays empty; `raster` may be NULL
/// when the caller only accepts strokes.
sp_result sp_drawing_read(const char* path, sp_sketch* sketch, sp_raster* raster, sp_error* err);
/// Loads a labelled folder: `dir/<category>/*.{json,svg,png}` and `dir/<category>.ndjson`.
/// Files are read in name order so that sample indices (and folds) are reproducible.
/// Fails on the first unreadable file, naming it.
sp_result sp_dataset_load(const char* dir, sp_dataset* out, sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
