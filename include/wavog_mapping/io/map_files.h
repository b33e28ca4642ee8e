// The file names and picture crop shared by every writer of a finished map (wavog_offline's
// output folder, the mapper's ~save_map): one naming scheme for scales and one crop, so that both
// write the same files for the same map. Free functions without state: thread-safe. wavog_io.
#ifndef WAVOG_MAPPING_IO_MAP_FILES_H_
#define WAVOG_MAPPING_IO_MAP_FILES_H_

#include <string>

#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

/// Unknown cells kept around the known part of a cropped raster (in raster cells).
constexpr int kCropMargin = 2;

/// Base name (without extension) of the pictures of scale `scale` beside a map whose path without
/// extension is `stem`: "<stem>_s<scale>" (wavog_offline: <out>/map.wavog, <out>/map_s0.pgm, ...).
std::string scaleFileBase(const std::string& stem, int scale);

/// `path` without its extension ("dir/room.wavog" -> "dir/room"; a dot in a folder name is kept).
std::string pathStem(const std::string& path);

/// The raster cut to the box of its known cells grown by `margin` cells on each side (clipped to
/// the raster); the raster unchanged if nothing is known.
Raster cropToKnown(const Raster& raster, int margin = kCropMargin);

/// Box (in the raster's scale-s cells) of the known cells of `raster`; false if none is known.
bool knownBox(const Raster& raster, CellBox* box);

}  // namespace wavog

#endif  // WAVOG_MAPPING_IO_MAP_FILES_H_
