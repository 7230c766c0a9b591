#include "taiga/io/point_fields.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cassert>
#include <cstring>
#include <limits>
#include <numbers>

#include "taiga/core/errors.hpp"

namespace taiga::io {

namespace {

/// unpackValue, inlined into the decoding loop: a call per value was a third of it (read_bench).
[[gnu::always_inline]] inline double unpackInline(const std::uint8_t* p, FieldType type,
                                                  bool swap) {
  // Each type copies its own constant number of bytes: a copy of a size known only at run time
  // was a call into the C library per value, the largest part of decoding a scan.
  auto as = [p, swap]<class T>(T) {
    std::uint8_t bytes[sizeof(T)];
    if (swap)
      std::reverse_copy(p, p + sizeof(T), bytes);
    else
      std::memcpy(bytes, p, sizeof(T));
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return static_cast<double>(value);
  };
  switch (type) {
    case FieldType::kInt8: return as(std::int8_t{});
    case FieldType::kUint8: return as(std::uint8_t{});
    case FieldType::kInt16: return as(std::int16_t{});
    case FieldType::kUint16: return as(std::uint16_t{});
    case FieldType::kInt32: return as(std::int32_t{});
    case FieldType::kUint32: return as(std::uint32_t{});
    case FieldType::kFloat32: return as(float{});
    case FieldType::kFloat64: return as(double{});
    case FieldType::kInt64: return as(std::int64_t{});
    case FieldType::kUint64: return as(std::uint64_t{});
  }
  return std::nan("");
}

}  // namespace

double unpackValue(const std::uint8_t* p, FieldType type, bool swap) {
  return unpackInline(p, type, swap);
}

namespace {

bool isInteger(FieldType type) { return type != FieldType::kFloat32 && type != FieldType::kFloat64; }

const PointField* findField(const std::vector<PointField>& fields, std::string_view name) {
  for (const PointField& f : fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

void checkLayout(const PackedPoints& points) {
  const std::uint64_t count = std::uint64_t{points.width} * points.height;
  if (count == 0) return;
  if (points.point_step == 0) throw InputError("point_step is 0 for a non-empty cloud");
  for (const PointField& f : points.fields) {
    const std::size_t size = fieldTypeSize(f.type);
    if (size == 0) {
      throw InputError(fmt::format("field '{}' has unknown datatype {}", f.name, static_cast<int>(f.type)));
    }
    if (std::uint64_t{f.offset} + size * std::max<std::uint64_t>(f.count, 1) > points.point_step) {
      throw InputError(fmt::format("field '{}' (offset {}, {} x {}) does not fit in point_step {}", f.name,
                                   f.offset, std::max<std::uint32_t>(f.count, 1), fieldTypeName(f.type),
                                   points.point_step));
    }
  }
  if (std::uint64_t{points.row_step} < std::uint64_t{points.width} * points.point_step) {
    throw InputError(fmt::format("row_step {} is smaller than width {} x point_step {}", points.row_step,
                                 points.width, points.point_step));
  }
  const std::uint64_t needed =
      std::uint64_t{points.row_step} * (points.height - 1) + std::uint64_t{points.width} * points.point_step;
  if (points.data.size() < needed) {
    throw InputError(fmt::format("data holds {} bytes but {} x {} points of {} bytes need {}", points.data.size(),
                                 points.height, points.width, points.point_step, needed));
  }
}

struct TimeRule {
  const PointField* field = nullptr;
  bool absolute = false;
  double scale_to_s = 1.0;
  std::string description;
};

// Absolute times in float64: seconds since the epoch are ~1.7e9, so the magnitude tells the unit.
double absoluteScale(double magnitude) {
  if (magnitude > 1e17) return 1e-9;
  if (magnitude > 1e14) return 1e-6;
  if (magnitude > 1e11) return 1e-3;
  return 1.0;
}

TimeRule chooseTimeRule(const PackedPoints& points, const PointDecodeOptions& options) {
  TimeRule rule;
  if (!options.time_field.empty()) {
    rule.field = findField(points.fields, options.time_field);
    if (!rule.field) {
      throw InputError(fmt::format("the configured time field '{}' is not among the fields ({})",
                                   options.time_field, describeFields(points.fields)));
    }
  } else {
    for (const char* name : {"t", "time", "offset_time", "timestamp"}) {
      if ((rule.field = findField(points.fields, name))) break;
    }
  }
  if (!rule.field) return rule;
  const FieldType type = rule.field->type;
  if (isInteger(type)) {
    rule.scale_to_s = 1e-9;
    rule.description = fmt::format("field '{}' ({}, ns after the stamp)", rule.field->name, fieldTypeName(type));
  } else if (type == FieldType::kFloat64 && rule.field->name != "time" && rule.field->name != "t") {
    rule.absolute = true;  // scale decided from the first value
    rule.description = fmt::format("field '{}' (float64, absolute)", rule.field->name);
  } else {
    rule.description = fmt::format("field '{}' ({}, s after the stamp)", rule.field->name, fieldTypeName(type));
  }
  return rule;
}

// Clockwise sweep angle from `start_rad` to `azimuth_rad`, in [0, 2 pi): spinning lidars
// (Velodyne, Ouster) turn clockwise seen from above, so azimuth decreases with time.
double clockwiseSweep(double start_rad, double azimuth_rad) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double sweep = std::fmod(start_rad - azimuth_rad, kTwoPi);
  if (sweep < 0.0) sweep += kTwoPi;
  return sweep;
}

// A cloud in firing order (column after column, as Velodyne and flattened column-major Ouster
// clouds are) fires the beams of one column at azimuths up to +-9 deg apart (the OS0's stagger),
// so near the start some of the first column's points lie counter-clockwise of the first point
// and the azimuth rule gives them a whole sweep (and some of the last column's none): a tear at
// the seam. In such a cloud a point's place in the order says which end of the sweep it belongs
// to. `sweep_fractions` are the clockwise sweeps over 2 pi, in the cloud's order; a fraction
// more than half a sweep from the point's place is moved by one sweep towards it. Only when at
// least 90 % of the points lie within a quarter sweep of their place (a cloud published beam
// after beam lies nowhere near it) and the cloud is not tiny.
void unwrapInFiringOrder(std::vector<double>& sweep_fractions) {
  const std::size_t n = sweep_fractions.size();
  if (n < 100) return;
  auto place = [n](std::size_t i) { return (static_cast<double>(i) + 0.5) / static_cast<double>(n); };
  std::size_t near = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = std::abs(sweep_fractions[i] - place(i));
    near += std::min(d, 1.0 - d) < 0.25;
  }
  if (near < 0.9 * static_cast<double>(n)) return;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = sweep_fractions[i] - place(i);
    if (d > 0.5) sweep_fractions[i] -= 1.0;
    if (d < -0.5) sweep_fractions[i] += 1.0;
  }
}

}  // namespace

std::size_t fieldTypeSize(FieldType type) {
  switch (type) {
    case FieldType::kInt8:
    case FieldType::kUint8: return 1;
    case FieldType::kInt16:
    case FieldType::kUint16: return 2;
    case FieldType::kInt32:
    case FieldType::kUint32:
    case FieldType::kFloat32: return 4;
    case FieldType::kFloat64:
    case FieldType::kInt64:
    case FieldType::kUint64: return 8;
  }
  return 0;
}

std::string fieldTypeName(FieldType type) {
  switch (type) {
    case FieldType::kInt8: return "int8";
    case FieldType::kUint8: return "uint8";
    case FieldType::kInt16: return "int16";
    case FieldType::kUint16: return "uint16";
    case FieldType::kInt32: return "int32";
    case FieldType::kUint32: return "uint32";
    case FieldType::kFloat32: return "float32";
    case FieldType::kFloat64: return "float64";
    case FieldType::kInt64: return "int64";
    case FieldType::kUint64: return "uint64";
  }
  return fmt::format("type{}", static_cast<int>(type));
}

bool fitsFieldType(FieldType type, double value) {
  auto within = []<class T>(T, double v) {
    return std::isfinite(v) && v == std::trunc(v) && v >= static_cast<double>(std::numeric_limits<T>::lowest()) &&
           v < std::ldexp(1.0, std::numeric_limits<T>::digits) ;
  };
  switch (type) {
    case FieldType::kInt8: return within(std::int8_t{}, value);
    case FieldType::kUint8: return within(std::uint8_t{}, value);
    case FieldType::kInt16: return within(std::int16_t{}, value);
    case FieldType::kUint16: return within(std::uint16_t{}, value);
    case FieldType::kInt32: return within(std::int32_t{}, value);
    case FieldType::kUint32: return within(std::uint32_t{}, value);
    case FieldType::kInt64: return within(std::int64_t{}, value);
    case FieldType::kUint64: return within(std::uint64_t{}, value);
    case FieldType::kFloat32:
    case FieldType::kFloat64: return true;
  }
  return false;
}

void packValue(std::uint8_t* p, FieldType type, double value) {
  assert(fitsFieldType(type, value));
  auto put = [p]<class T>(T typed) { std::memcpy(p, &typed, sizeof(T)); };
  switch (type) {
    case FieldType::kInt8: put(static_cast<std::int8_t>(value)); break;
    case FieldType::kUint8: put(static_cast<std::uint8_t>(value)); break;
    case FieldType::kInt16: put(static_cast<std::int16_t>(value)); break;
    case FieldType::kUint16: put(static_cast<std::uint16_t>(value)); break;
    case FieldType::kInt32: put(static_cast<std::int32_t>(value)); break;
    case FieldType::kUint32: put(static_cast<std::uint32_t>(value)); break;
    case FieldType::kFloat32: put(static_cast<float>(value)); break;
    case FieldType::kFloat64: put(value); break;
    case FieldType::kInt64: put(static_cast<std::int64_t>(value)); break;
    case FieldType::kUint64: put(static_cast<std::uint64_t>(value)); break;
  }
}

std::string describeFields(const std::vector<PointField>& fields) {
  std::string out;
  for (const PointField& f : fields) {
    if (!out.empty()) out += ' ';
    out += fmt::format("{}:{}", f.name, fieldTypeName(f.type));
    if (f.count > 1) out += fmt::format("[{}]", f.count);
  }
  return out;
}

namespace {

/// The fields decodeRecords reads besides the positions' (null when absent).
struct DecodeFields {
  const PointField *x, *y, *z, *intensity, *ring;
  const TimeRule* time;
};

/// Positions whose three fields are T in the machine's byte order.
template <class T>
struct TypedXyz {
  Eigen::Vector3d operator()(const std::uint8_t* record, const DecodeFields& f) const {
    auto at = [record](const PointField* field) {
      T value;
      std::memcpy(&value, record + field->offset, sizeof(T));
      return static_cast<double>(value);
    };
    return {at(f.x), at(f.y), at(f.z)};
  }
};

/// Positions of any float types and byte order.
struct AnyXyz {
  bool swap = false;
  Eigen::Vector3d operator()(const std::uint8_t* record, const DecodeFields& f) const {
    return {unpackInline(record + f.x->offset, f.x->type, swap),
            unpackInline(record + f.y->offset, f.y->type, swap),
            unpackInline(record + f.z->offset, f.z->type, swap)};
  }
};

/// Every record of the cloud in order: its position by `xyz`, its time by the rule, intensity
/// and ring; a record without a finite, non-zero position or a finite time is counted and left.
/// Returns the absolute times' scale to seconds (0 without absolute times).
template <class Xyz>
double decodeRecords(const PackedPoints& points, double stamp_s, const PointDecodeOptions& options,
                     const DecodeFields& f, bool swap, Xyz xyz, DecodedPoints& out) {
  const TimeRule& time_rule = *f.time;
  const PointField* f_intensity = f.intensity;
  const PointField* f_ring = f.ring;
  const bool organized = points.height > 1;
  PointCloud& cloud = out.cloud;
  const std::size_t count = std::size_t{points.width} * points.height;
  cloud.reserve(count);
  double absolute_scale = 0.0;  // 0 until the first absolute time is seen
  std::optional<double> start_azimuth_rad;

  for (std::uint32_t row = 0; row < points.height; ++row) {
    for (std::uint32_t col = 0; col < points.width; ++col) {
      const std::uint8_t* record = points.data.data() + std::size_t{row} * points.row_step + std::size_t{col} * points.point_step;
      const Eigen::Vector3d p = xyz(record, f);
      if (!p.allFinite() || p.isZero(0.0)) {
        ++out.dropped_invalid;
        continue;
      }
      double t_s = stamp_s;
      if (options.deskewed) {
        // every point at the stamp
      } else if (time_rule.field) {
        const double value =
            unpackInline(record + time_rule.field->offset, time_rule.field->type, swap);
        if (time_rule.absolute) {
          if (absolute_scale == 0.0) absolute_scale = absoluteScale(std::abs(value));
          t_s = value * absolute_scale;
        } else {
          t_s = stamp_s + value * time_rule.scale_to_s;
        }
      } else if (organized) {
        t_s = stamp_s + options.scan_period_s * col / points.width;
      } else {  // a sweep fraction for now, times below
        const double azimuth_rad = std::atan2(p.y(), p.x());
        if (!start_azimuth_rad) start_azimuth_rad = azimuth_rad;
        t_s = clockwiseSweep(*start_azimuth_rad, azimuth_rad) / (2.0 * std::numbers::pi);
      }
      if (!std::isfinite(t_s)) {
        ++out.dropped_invalid;
        continue;
      }
      cloud.positions.push_back(p);
      cloud.times_s.push_back(t_s);
      if (f_intensity)
        cloud.intensities.push_back(static_cast<float>(
            unpackInline(record + f_intensity->offset, f_intensity->type, swap)));
      if (f_ring) {
        cloud.rings.push_back(
            static_cast<std::uint16_t>(unpackInline(record + f_ring->offset, f_ring->type, swap)));
      } else if (organized) {
        cloud.rings.push_back(static_cast<std::uint16_t>(row));
      }
      if (organized) cloud.columns.push_back(static_cast<std::uint16_t>(col));
    }
  }

  return absolute_scale;
}

}  // namespace

DecodedPoints decodePackedPoints(const PackedPoints& points, double stamp_s,
                                 const PointDecodeOptions& options) {
  checkLayout(points);
  const PointField* fx = findField(points.fields, "x");
  const PointField* fy = findField(points.fields, "y");
  const PointField* fz = findField(points.fields, "z");
  if (!fx || !fy || !fz) {
    throw InputError(fmt::format("the points have no x, y and z fields (fields: {})",
                                 describeFields(points.fields)));
  }
  for (const PointField* f : {fx, fy, fz}) {
    if (isInteger(f->type))
      throw InputError(fmt::format("field '{}' is {}, expected float32 or float64", f->name,
                                   fieldTypeName(f->type)));
  }
  const PointField* f_intensity = findField(points.fields, "reflectivity");
  if (!f_intensity) f_intensity = findField(points.fields, "intensity");
  const PointField* f_ring = findField(points.fields, "ring");
  if (!f_ring) f_ring = findField(points.fields, "line");
  const bool organized = points.height > 1;
  const TimeRule time_rule = chooseTimeRule(points, options);
  const bool swap = points.is_bigendian != (std::endian::native == std::endian::big);
  DecodedPoints out;
  double absolute_scale = 0.0;
  const DecodeFields fields{fx, fy, fz, f_intensity, f_ring, &time_rule};
  const auto all = [&](FieldType type) {
    return fx->type == type && fy->type == type && fz->type == type;
  };
  // The positions are most of the bytes: read with their type known at compile time when the
  // three share it (a reading switched per value was half of decoding a scan, bench/read_bench).
  if (all(FieldType::kFloat32) && !swap) {
    absolute_scale = decodeRecords(points, stamp_s, options, fields, swap, TypedXyz<float>{}, out);
  } else if (all(FieldType::kFloat64) && !swap) {
    absolute_scale = decodeRecords(points, stamp_s, options, fields, swap, TypedXyz<double>{}, out);
  } else {
    absolute_scale = decodeRecords(points, stamp_s, options, fields, swap, AnyXyz{swap}, out);
  }
  if (options.deskewed) {
    out.time_source = PointTimeSource::kStamp;
    out.time_description = "deskewed upstream (recording.deskewed): every point at the stamp";
  } else if (time_rule.field) {
    out.time_source = time_rule.absolute ? PointTimeSource::kAbsoluteField : PointTimeSource::kRelativeField;
    out.time_description = time_rule.description;
    if (time_rule.absolute) {
      const char* unit = absolute_scale == 1e-9 ? "ns" : absolute_scale == 1e-6 ? "us" : absolute_scale == 1e-3 ? "ms" : "s";
      out.time_description = fmt::format("{} in {}", time_rule.description, unit);
    }
  } else if (organized) {
    out.time_source = PointTimeSource::kColumnIndex;
    out.time_description = fmt::format("no time field: derived from the column index over a {} s sweep", options.scan_period_s);
  } else {  // the loop left sweep fractions
    unwrapInFiringOrder(out.cloud.times_s);
    for (double& t_s : out.cloud.times_s) t_s = stamp_s + options.scan_period_s * t_s;
    out.time_source = PointTimeSource::kAzimuth;
    out.time_description = fmt::format("no time field: derived from the clockwise azimuth over a {} s sweep", options.scan_period_s);
  }
  return out;
}

}  // namespace taiga::io
