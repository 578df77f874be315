#!/usr/bin/python3
"""The evaluation figures (sss-report, sss-eval --plot) drawn with matplotlib.

Reads FIGURE_DATA/figures.json, which the C++ side writes (tools/eval/figure_script.hpp), with its
rasters as .npy files beside it, and writes each figure's PNG into OUT_DIR. One function per kind
of figure; colours come from matplotlib's tab10 cycle ("C1" orange = DR, "C9" cyan = SLAM) so an
estimate keeps its colour across figures. Maps: east to the right, north up, equal scale, metres.

Exit codes: 0 every figure written; 1 some figures failed (one line each on stderr, the others are
written); 2 bad arguments or unreadable figures.json; 3 matplotlib or numpy missing.
"""

import argparse
import json
import math
import os
import sys

try:
    import numpy as np
    import matplotlib

    matplotlib.use("Agg")  # files only, no display
    import matplotlib.pyplot as plt
    from matplotlib import patheffects
    from matplotlib.collections import LineCollection
    from matplotlib.colors import LightSource, Normalize
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar
except ImportError as error:
    print(f"report_figures.py: {error} for {sys.executable}: install python3-matplotlib (tools/setup-deps.sh)",
          file=sys.stderr)
    sys.exit(3)

DPI = 100
NO_DATA_GREY = "#c8c8c8"
MARGIN_FRACTION = 0.04


# ---- helpers -------------------------------------------------------------------------------

def nice_ceil(value):
    """Round up to 1, 2 or 5 x 10^k (the C++ niceCeil)."""
    if not (value > 0.0) or not math.isfinite(value):
        return 1.0
    magnitude = 10.0 ** math.floor(math.log10(value))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * magnitude >= value * (1.0 - 1e-12):
            return m * magnitude
    return 10.0 * magnitude


def nice_floor(value):
    """Round down to 1, 2 or 5 x 10^k: a scale-bar length."""
    if not (value > 0.0):
        return 1.0
    magnitude = 10.0 ** math.floor(math.log10(value))
    for m in (5.0, 2.0, 1.0):
        if m * magnitude <= value:
            return m * magnitude
    return magnitude


def colour(index):
    return f"C{int(index) % 10}"


def load_raster(data_dir, raster):
    return np.load(os.path.join(data_dir, raster["npy"]), allow_pickle=False)


def mosaic_extent(raster, image):
    """imshow extent (east_min, east_max, north_min, north_max) of a mosaic: row 0 northmost,
    pixel (r, c) centred at north_max - (r + 0.5) res, east_min + (c + 0.5) res."""
    res = raster["resolution_m"]
    rows, cols = image.shape
    return (raster["east_min_m"], raster["east_min_m"] + cols * res, raster["north_max_m"] - rows * res,
            raster["north_max_m"])


def heightmap_extent(raster, values):
    """imshow extent of a heightmap: row 0 southmost, cell (r, c) centred at north_min + r res,
    east_min + c res (heightmap_metrics.hpp)."""
    res = raster["resolution_m"]
    rows, cols = values.shape
    return (raster["east_min_m"] - 0.5 * res, raster["east_min_m"] + (cols - 0.5) * res,
            raster["north_min_m"] - 0.5 * res, raster["north_min_m"] + (rows - 0.5) * res)


def data_bounds(mask, extent, row0_north):
    """(east_min, east_max, north_min, north_max) of the pixels where mask is set; None if none."""
    rows, cols = mask.shape
    if not mask.any():
        return None
    row_index = np.flatnonzero(mask.any(axis=1))
    col_index = np.flatnonzero(mask.any(axis=0))
    east_step = (extent[1] - extent[0]) / cols
    north_step = (extent[3] - extent[2]) / rows
    east = (extent[0] + col_index[0] * east_step, extent[0] + (col_index[-1] + 1) * east_step)
    if row0_north:
        north = (extent[3] - (row_index[-1] + 1) * north_step, extent[3] - row_index[0] * north_step)
    else:
        north = (extent[2] + row_index[0] * north_step, extent[2] + (row_index[-1] + 1) * north_step)
    return (east[0], east[1], north[0], north[1])


def union(bounds_list):
    bounds_list = [b for b in bounds_list if b is not None]
    if not bounds_list:
        return None
    return (min(b[0] for b in bounds_list), max(b[1] for b in bounds_list), min(b[2] for b in bounds_list),
            max(b[3] for b in bounds_list))


def points_bounds(north_east):
    points = np.asarray(north_east, dtype=float).reshape(-1, 2)
    points = points[np.isfinite(points).all(axis=1)]
    if len(points) == 0:
        return None
    return (points[:, 1].min(), points[:, 1].max(), points[:, 0].min(), points[:, 0].max())


def with_margin(bounds, fraction=MARGIN_FRACTION, min_span_m=1.0):
    east_span = max(bounds[1] - bounds[0], min_span_m)
    north_span = max(bounds[3] - bounds[2], min_span_m)
    east_centre, north_centre = 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3])
    half_east, half_north = 0.5 * east_span * (1 + 2 * fraction), 0.5 * north_span * (1 + 2 * fraction)
    return (east_centre - half_east, east_centre + half_east, north_centre - half_north, north_centre + half_north)


def map_figsize(bounds, width_in, extra_height_in, columns=1):
    """Figure size in inches for equal-aspect maps of these bounds; height kept in 4..14 in."""
    aspect = (bounds[3] - bounds[2]) / max(bounds[1] - bounds[0], 1e-9)
    height = (width_in / columns) * aspect + extra_height_in
    return (width_in, min(max(height, 4.0), 14.0))


def set_map_axes(ax, bounds, label_north=True):
    ax.set_xlim(bounds[0], bounds[1])
    ax.set_ylim(bounds[2], bounds[3])
    ax.set_aspect("equal")
    ax.set_xlabel("east (m)")
    if label_north:
        ax.set_ylabel("north (m)")
    ax.tick_params(labelsize=9)


def add_scale_bar(ax, bounds):
    length_m = nice_floor((bounds[1] - bounds[0]) / 5.0)
    label = f"{length_m:g} m"
    bar = AnchoredSizeBar(ax.transData, length_m, label, "lower right", pad=0.4, borderpad=0.6, sep=3,
                          frameon=True, size_vertical=0)
    bar.patch.set_alpha(0.8)
    ax.add_artist(bar)


def masked_mosaic(image):
    """8-bit mosaic with 0 = no data as a masked array (shown as the axes' background)."""
    return np.ma.masked_equal(np.asarray(image), 0)


def title_with_note(fig, ax, spec):
    fig.suptitle(spec.get("title", ""), fontsize=13)
    if spec.get("note"):
        ax.set_title(spec["note"], fontsize=9, color="#555555")


def save(fig, out_dir, spec):
    fig.savefig(os.path.join(out_dir, spec["file"]), dpi=DPI)
    plt.close(fig)


# ---- figures -------------------------------------------------------------------------------

def draw_map(spec, data_dir, out_dir):
    """Lines and segments over an optional mosaic (trajectories, the loop-closure graph)."""
    background = spec.get("background")
    image = load_raster(data_dir, background) if background else None
    extent = mosaic_extent(background, image) if background else None
    bounds = [data_bounds(image > 0, extent, row0_north=True)] if background else []
    for line in spec.get("lines", []):
        bounds.append(points_bounds(line["north_east_m"]))
    for segments in spec.get("segments", []):
        for a, b in segments["north_east_m"]:
            bounds.append(points_bounds([a, b]))
    bounds = union(bounds)
    if bounds is None:
        raise ValueError("nothing to draw (no mosaic data, no points)")
    bounds = with_margin(bounds)

    fig = plt.figure(figsize=map_figsize(bounds, 11.0, 1.6), dpi=DPI, layout="constrained")
    ax = fig.add_subplot()
    # Light grey around a mosaic, so the white truth line stays visible off it.
    ax.set_facecolor("#e6e6e6" if background else "white")
    if background:
        # Faded under busy overlays (the closure graph), so the overlay reads first.
        ax.imshow(masked_mosaic(image), cmap="gray", vmin=0, vmax=255, extent=extent, origin="upper",
                  interpolation="antialiased", alpha=background.get("alpha", 1.0))
    for line in spec.get("lines", []):
        points = np.asarray(line["north_east_m"], dtype=float).reshape(-1, 2)
        if len(points) == 0:
            continue
        width = line.get("width", 1.5)
        if line.get("truth"):
            # Truth: white with a black outline over a mosaic, black on white paper.
            if background:
                artist, = ax.plot(points[:, 1], points[:, 0], color="white", lw=width, label=line["label"], zorder=3)
                artist.set_path_effects([patheffects.Stroke(linewidth=width + 2, foreground="black"),
                                         patheffects.Normal()])
            else:
                ax.plot(points[:, 1], points[:, 0], color="black", lw=width, label=line["label"], zorder=4)
        else:
            ax.plot(points[:, 1], points[:, 0], color=line.get("colour", "C0"), lw=width, label=line["label"],
                    zorder=3)
        if line.get("mark_start"):
            ax.plot(points[0, 1], points[0, 0], "o", ms=11, mfc="none", mec="black", mew=1.5, zorder=5)
            ax.annotate("start", (points[0, 1], points[0, 0]), xytext=(8, 8), textcoords="offset points",
                        fontsize=9, path_effects=[patheffects.withStroke(linewidth=3, foreground="white")])
    for segments in spec.get("segments", []):
        pairs = [[(a[1], a[0]), (b[1], b[0])] for a, b in segments["north_east_m"]]
        ax.add_collection(LineCollection(pairs, colors=segments.get("colour", "C0"), linewidths=2,
                                         label=segments["label"], zorder=4))
        if pairs:  # the subframe centres themselves
            ends = np.asarray(pairs, dtype=float).reshape(-1, 2)
            ax.plot(ends[:, 0], ends[:, 1], "o", ms=4, color=segments.get("colour", "C0"), zorder=4)
    set_map_axes(ax, bounds)
    add_scale_bar(ax, bounds)
    ax.legend(loc="best", fontsize=9, framealpha=0.9)
    title_with_note(fig, ax, spec)
    save(fig, out_dir, spec)


def draw_curves(spec, data_dir, out_dir):
    """Curves over x (e.g. error over time) with shaded, labelled bands (survey lines)."""
    fig = plt.figure(figsize=(12.0, 5.5), dpi=DPI, layout="constrained")
    ax = fig.add_subplot()
    for k, band in enumerate(spec.get("bands", [])):
        # Labelled just above the plot, where neither the curves nor the legend cover them.
        ax.axvspan(band["x_min"], band["x_max"], color="#e8ecf2", zorder=0,
                   label="survey line (shaded)" if k == 0 else None)
        ax.text(0.5 * (band["x_min"] + band["x_max"]), 1.005, band["label"], transform=ax.get_xaxis_transform(),
                ha="center", va="bottom", fontsize=9, color="#555555")
    drawn = 0
    for curve in spec.get("curves", []):
        x = np.asarray(curve["x"], dtype=float)
        y = np.asarray(curve["y"], dtype=float)
        if len(x) == 0:
            continue
        dashed = curve.get("dashed", False)  # the secondary (aligned) curve: thinner
        ax.plot(x, y, color=curve.get("colour", "C0"), lw=1.2 if dashed else 2.2, ls="--" if dashed else "-",
                label=curve["label"])
        drawn += 1
    if drawn == 0:
        raise ValueError("no curve has points")
    ax.set_ylim(bottom=0.0)
    ax.margins(x=0.01)
    ax.grid(True, color="#d0d0d0", lw=0.6)
    ax.set_axisbelow(True)
    ax.set_xlabel(spec.get("x_label", ""))
    ax.set_ylabel(spec.get("y_label", ""))
    ax.legend(loc="best", fontsize=9, framealpha=0.9)
    fig.suptitle(spec.get("title", ""), fontsize=13)
    save(fig, out_dir, spec)


def draw_mosaics(spec, data_dir, out_dir):
    """Mosaics side by side at one extent (the union of their data) and one scale."""
    panels = [(panel, load_raster(data_dir, panel)) for panel in spec["panels"]]
    extents = [mosaic_extent(panel, image) for panel, image in panels]
    bounds = union([data_bounds(image > 0, extent, row0_north=True) for (_, image), extent in zip(panels, extents)])
    if bounds is None:
        raise ValueError("the mosaics have no data")
    bounds = with_margin(bounds, 0.02)
    # Height for the maps' aspect at the panels' width less the axes' labels (about 0.9 in each).
    width_in = 15.6
    figsize = map_figsize(bounds, width_in - 0.9 * len(panels), 1.0, len(panels))
    fig, axes = plt.subplots(1, len(panels), figsize=(width_in, figsize[1]), dpi=DPI, layout="constrained",
                             sharex=True, sharey=True, squeeze=False)
    for k, ((panel, image), extent) in enumerate(zip(panels, extents)):
        ax = axes[0][k]
        ax.set_facecolor(NO_DATA_GREY)  # not black: shadows are dark
        ax.imshow(masked_mosaic(image), cmap="gray", vmin=0, vmax=255, extent=extent, origin="upper",
                  interpolation="antialiased")
        set_map_axes(ax, bounds, label_north=(k == 0))
        ax.set_title(panel["label"], fontsize=11)
        add_scale_bar(ax, bounds)
    fig.suptitle(spec.get("title", "") + "\nsame extent and scale, north up; light grey = no data", fontsize=12)
    save(fig, out_dir, spec)


def raster_axes(bounds):
    fig = plt.figure(figsize=map_figsize(bounds, 9.0, 1.9), dpi=DPI, layout="constrained")
    ax = fig.add_subplot()
    ax.set_facecolor(NO_DATA_GREY)
    return fig, ax


def draw_depth(spec, data_dir, out_dir):
    """A heightmap: depth in viridis (shallow yellow, deep purple) between the 1st and 99th
    percentiles, hill-shaded from the north-west so relief and artefacts show; grey = no data."""
    raster = spec["raster"]
    depth = np.asarray(load_raster(data_dir, raster), dtype=float)
    valid = np.isfinite(depth)
    if not valid.any():
        raise ValueError("the heightmap has no data")
    extent = heightmap_extent(raster, depth)
    shallow_m, deep_m = np.percentile(depth[valid], [1.0, 99.0])
    if deep_m - shallow_m < 1e-3:
        shallow_m, deep_m = shallow_m - 0.5, deep_m + 0.5
    bounds = with_margin(data_bounds(valid, extent, row0_north=False), 0.02)
    fig, ax = raster_axes(bounds)
    norm = Normalize(vmin=shallow_m, vmax=deep_m)
    cmap = plt.get_cmap("viridis_r")
    if spec.get("hillshade", True):
        # Elevation = -depth; rows flipped so row 0 is at the top as LightSource expects (north up).
        elevation = np.where(valid, -depth, -np.nanmedian(depth[valid]))[::-1]
        light = LightSource(azdeg=315, altdeg=45)
        rgb = light.shade(elevation, cmap=plt.get_cmap("viridis"), norm=Normalize(-deep_m, -shallow_m),
                          blend_mode="soft", dx=raster["resolution_m"], dy=raster["resolution_m"])
        rgb[..., 3] = valid[::-1]  # no data: transparent, the grey background shows
        ax.imshow(rgb, extent=extent, origin="upper", interpolation="antialiased")
    else:
        ax.imshow(np.ma.masked_invalid(depth), cmap=cmap, norm=norm, extent=extent, origin="lower",
                  interpolation="antialiased")
    set_map_axes(ax, bounds)
    add_scale_bar(ax, bounds)
    bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, orientation="horizontal", shrink=0.7,
                       pad=0.02, aspect=40)
    bar.set_label("depth below the origin (m), 1st-99th percentile: yellow = shallow, purple = deep, grey = no data")
    fig.suptitle(spec.get("title", ""), fontsize=13)
    save(fig, out_dir, spec)


def draw_error_map(spec, data_dir, out_dir):
    """Estimate minus truth (depth, positive down) on a diverging scale +-limit: blue = estimate
    shallower, white = 0, red = estimate deeper, grey = no data."""
    raster = spec["raster"]
    error = np.asarray(load_raster(data_dir, raster), dtype=float)
    valid = np.isfinite(error)
    if not valid.any():
        raise ValueError("the error map has no data")
    limit_m = spec.get("limit_m", 0.0)
    if not (limit_m > 0.0):
        limit_m = nice_ceil(max(float(np.percentile(np.abs(error[valid]), 99.0)), 1e-3))
    extent = heightmap_extent(raster, error)
    bounds = with_margin(data_bounds(valid, extent, row0_north=False), 0.02)
    fig, ax = raster_axes(bounds)
    image = ax.imshow(np.ma.masked_invalid(error), cmap="RdBu_r", vmin=-limit_m, vmax=limit_m, extent=extent,
                      origin="lower", interpolation="nearest")
    set_map_axes(ax, bounds)
    add_scale_bar(ax, bounds)
    bar = fig.colorbar(image, ax=ax, orientation="horizontal", shrink=0.7, pad=0.02, aspect=40, extend="both")
    bar.set_label(f"estimate - truth depth (m), scale +-{limit_m:g} m: blue = shallower, red = deeper, grey = no data")
    fig.suptitle(spec.get("title", ""), fontsize=13)
    save(fig, out_dir, spec)


DRAW = {"map": draw_map, "curves": draw_curves, "mosaics": draw_mosaics, "depth": draw_depth,
        "error_map": draw_error_map}


def main():
    parser = argparse.ArgumentParser(description="Draws the evaluation figures described by FIGURE_DATA/figures.json.")
    parser.add_argument("figure_data", help="folder with figures.json and its .npy rasters (written by sss-report / sss-eval)")
    parser.add_argument("out_dir", help="folder the PNGs are written to")
    args = parser.parse_args()
    spec_path = os.path.join(args.figure_data, "figures.json")
    try:
        with open(spec_path, encoding="utf-8") as spec_file:
            figures = json.load(spec_file)["figures"]
    except (OSError, ValueError, KeyError) as error:
        print(f"report_figures.py: {spec_path}: unreadable: {error}", file=sys.stderr)
        return 2
    failed = 0
    for spec in figures:
        try:
            DRAW[spec["kind"]](spec, args.figure_data, args.out_dir)
        except Exception as error:  # one bad figure must not cost the others
            plt.close("all")
            print(f"report_figures.py: {spec.get('file', '?')}: {type(error).__name__}: {error}", file=sys.stderr)
            failed += 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
