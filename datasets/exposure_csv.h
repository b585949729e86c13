#pragma once
// exposure.csv (datasets/FORMAT.md): the exposure of every camera at every frame of a dataset
// rendered with the sensor model.

#include <string>
#include <vector>

#include "datasets/dataset_validate.h"
#include "datasets/rig.h"

namespace rovo {

// One line of exposure.csv: the exposure of one camera at one dataset frame.
struct ExposureRow {
  int frame = 0;
  std::string camera;
  double exposure_ms = 0.0;
  double gain = 1.0;
  double meter_luminance = 0.0;  // the auto-exposure meter's centre-weighted mean luminance
  double dn_per_radiance = 0.0;  // mean ADC codes per unit scene radiance (before clipping)
  double dark_dn = 0.0;          // mean ADC codes of the dark signal
};

// exposure.csv (datasets/FORMAT.md): atomic write; the reader checks the header, every number and
// that the rows are frames 0..frame_count-1 with the cameras in rig order, and throws
// std::runtime_error naming the file, line and column.
void WriteExposureCsv(const std::string& path, const std::vector<ExposureRow>& rows);
std::vector<ExposureRow> ReadExposureCsv(const std::string& path, int frame_count, const Rig& rig);
// The reader's checks with every problem recorded as (path, "line N", message naming the column).
std::vector<ExposureRow> ParseExposureCsv(const std::string& text, const std::string& path, int frame_count,
                                          const Rig& rig, std::vector<ValidationIssue>* issues);

}  // namespace rovo
