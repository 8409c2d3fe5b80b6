// Reading schedules and resolving each frame's style.
#include "skybake/input/schedule.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "toml_reader.h"

#include "skybake/model/atmosphere.h"

namespace skybake {
namespace {

constexpr int kMaxFrames = 100000;

class ScheduleReader : public TomlReader {
 public:
  using TomlReader::Number;
  ScheduleReader(std::string file, std::vector<ConfigError>& errors) : TomlReader(std::move(file), errors) {}

  ConfigError Origin(const toml::node* node, const std::string& key) const {
    return LocatedError(file(), node ? node->source() : toml::source_region{}, key, "");
  }

  // A finite number (TomlReader::Number), when the key is given.
  std::optional<double> Number(const toml::node* node, const std::string& key) {
    if (!node) return std::nullopt;
    return Number(*node, key);
  }

  // A number, a list of numbers, or a {start, end, step} range.
  std::optional<std::vector<double>> Series(const toml::node* node, const std::string& key) {
    if (!node) return std::nullopt;
    if (node->is_number()) {
      std::optional<double> v = Number(node, key);
      if (!v) return std::nullopt;
      return std::vector<double>{*v};
    }
    if (const toml::array* array = node->as_array()) {
      std::vector<double> values;
      for (size_t i = 0; i < array->size(); ++i) {
        std::optional<double> v = Number(array->get(i), fmt::format("{}[{}]", key, i));
        if (!v) return std::nullopt;
        values.push_back(*v);
      }
      if (values.empty()) {
        Error(node, key, "the list is empty");
        return std::nullopt;
      }
      return values;
    }
    if (const toml::table* range = node->as_table()) {
      std::optional<double> start = Number(range->get("start"), key + ".start");
      std::optional<double> end = Number(range->get("end"), key + ".end");
      std::optional<double> step = Number(range->get("step"), key + ".step");
      CheckKeys(*range, key, {"start", "end", "step"});
      if (!start || !end || !step) {
        if (!range->get("start") || !range->get("end") || !range->get("step"))
          Error(node, key, "a range needs start, end and step, e.g. { start = 0, end = 60, step = 5 }");
        return std::nullopt;
      }
      return Steps(node, key, *start, *end, *step);
    }
    Error(node, key, "expected a number, a list of numbers, or { start, end, step }");
    return std::nullopt;
  }

  // start, start + step, ... up to end inclusive (to a millionth of a step).
  std::optional<std::vector<double>> Steps(const toml::node* node, const std::string& key, double start,
                                           double end, double step) {
    if (step == 0.0 || (end - start) * step < 0.0) {
      Error(node, key,
            fmt::format("step {} cannot go from {} to {}: use a non-zero step with the sign of end - start",
                        step, start, end));
      return std::nullopt;
    }
    double count = std::floor((end - start) / step + 1e-6) + 1.0;
    if (count > kMaxFrames) {
      Error(node, key, fmt::format("{} frames is more than the limit of {}", count, kMaxFrames));
      return std::nullopt;
    }
    std::vector<double> values;
    for (int i = 0; i < int(count); ++i) values.push_back(start + i * step);
    return values;
  }

  // Reports keys of `table` outside `known`, with the nearest known one.
  void CheckKeys(const toml::table& table, const std::string& prefix, std::initializer_list<const char*> known) {
    for (const auto& [k, node] : table) {
      bool ok = false;
      for (const char* name : known) ok = ok || k.str() == name;
      if (!ok) {
        std::string names;
        for (const char* name : known) names += (names.empty() ? "'" : ", '") + std::string(name) + "'";
        Error(&node, prefix + "." + std::string(k.str()),
              fmt::format("unknown key '{}'{} (expected {})", k.str(), DidYouMean(k.str(), known), names));
      }
    }
  }

  std::optional<toml::time> Time(const toml::node* node, const std::string& key) {
    if (!node) return std::nullopt;
    if (const auto* t = node->as_time()) return t->get();
    Error(node, key, "expected a local time such as 09:30:00 (TOML time, no quotes)");
    return std::nullopt;
  }

  std::optional<toml::date> Date(const toml::node* node, const std::string& key) {
    if (!node) return std::nullopt;
    if (const auto* d = node->as_date()) return d->get();
    Error(node, key, "expected a date such as 2013-05-27 (TOML date, no quotes)");
    return std::nullopt;
  }

  // Whether `key` (dotted) can name a style key: non-empty parts of letters,
  // digits and '_'. Anything else (an '=' or a space) would be misread as an
  // assignment, so it is reported here, at its place in the schedule.
  bool StyleKeyName(const toml::node& node, const std::string& where, const std::string& key) {
    bool ok = !key.empty() && key.front() != '.' && key.back() != '.' && key.find("..") == std::string::npos;
    for (char c : key)
      ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.');
    if (!ok)
      Error(&node, where, fmt::format("'{}' is not a style key: use a dotted key such as \"atmosphere.mie.g\"", key));
    return ok;
  }

  // Flattens a table of style keys (quoted "a.b.c" or nested a.b.c) into
  // dotted keys with their TOML text.
  void Flatten(const toml::table& table, const std::string& prefix, std::vector<FrameOverride>& out,
               const std::string& where) {
    for (const auto& [k, node] : table) {
      std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
      if (!StyleKeyName(node, where + "." + key, key)) continue;
      if (const toml::table* sub = node.as_table()) {
        Flatten(*sub, key, out, where);
        continue;
      }
      FrameOverride o;
      o.key = key;
      o.toml_value = ValueText(node);
      o.origin = Origin(&node, key);
      out.push_back(std::move(o));
    }
  }

  // Flattens a table of numbers or RGB triples (ramps, rates).
  template <class F>
  void FlattenNumbers(const toml::table& table, const std::string& prefix, F each, const std::string& where) {
    for (const auto& [k, node] : table) {
      std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
      if (!StyleKeyName(node, where + "." + key, key)) continue;
      if (const toml::table* sub = node.as_table()) {
        FlattenNumbers(*sub, key, each, where);
        continue;
      }
      each(key, node);
    }
  }

  static std::string ValueText(const toml::node& node) {
    if (node.is_floating_point()) return fmt::format("{:.17g}", node.as_floating_point()->get());
    std::ostringstream out;
    node.visit([&](const auto& v) { out << v; });
    return out.str();
  }

};

CivilTime MakeCivilTime(const toml::date& date, const toml::time& time, double offset) {
  CivilTime t;
  t.year = date.year, t.month = date.month, t.day = date.day;
  t.hour = time.hour, t.minute = time.minute;
  t.second = time.second + time.nanosecond * 1e-9;
  t.utc_offset_hours = offset;
  return t;
}

std::string FormatReal(double v) { return fmt::format("{:.17g}", v); }

}  // namespace

ScheduleResult ParseSchedule(std::string_view toml_text, const std::string& name) {
  ScheduleResult result;
  Schedule& schedule = result.schedule;
  schedule.source_path = name;
  std::optional<toml::table> parsed = ParseTomlText(toml_text, name, result.errors);
  if (!parsed) return result;
  toml::table& root = *parsed;
  ScheduleReader r(name, result.errors);
  const toml::table* s = root["schedule"].as_table();
  if (!s) {
    r.Error(root.get("schedule"), "schedule", "no [schedule] table: add one (README \"Schedules\")");
    return result;
  }
  r.CheckKeys(*s, "schedule",
              {"first_frame", "date", "latitude_deg", "longitude_deg", "utc_offset_hours", "times", "sun",
               "frames", "ramp", "per_hour"});

  int first_frame = 1;
  if (const toml::node* n = s->get("first_frame")) {
    if (!n->is_integer() || n->as_integer()->get() < 1 || n->as_integer()->get() > 9999999)
      r.Error(n, "schedule.first_frame", "expected an integer in [1, 9999999]");
    else
      first_frame = int(n->as_integer()->get());
  }

  // Where and when, for clock times.
  std::optional<toml::date> date = r.Date(s->get("date"), "schedule.date");
  std::optional<double> latitude = r.Number(s->get("latitude_deg"), "schedule.latitude_deg");
  std::optional<double> longitude = r.Number(s->get("longitude_deg"), "schedule.longitude_deg");
  std::optional<double> offset = r.Number(s->get("utc_offset_hours"), "schedule.utc_offset_hours");
  if (latitude && std::abs(*latitude) > 90.0)
    r.Error(s->get("latitude_deg"), "schedule.latitude_deg", "latitude must be within [-90, 90]");
  if (longitude && std::abs(*longitude) > 180.0)
    r.Error(s->get("longitude_deg"), "schedule.longitude_deg", "longitude must be within [-180, 180], east positive");
  if (offset && std::abs(*offset) > 14.0)
    r.Error(s->get("utc_offset_hours"), "schedule.utc_offset_hours", "UTC offset must be within [-14, 14] hours");
  if (date && (date->month < 1 || date->month > 12 || date->day < 1 ||
               date->day > DaysInMonth(date->year, date->month)))
    r.Error(s->get("date"), "schedule.date", "not a calendar date");
  auto need_place = [&](const toml::node* where, const std::string& key) {
    bool ok = true;
    for (auto [field, value] : {std::pair{"latitude_deg", latitude.has_value()},
                                {"longitude_deg", longitude.has_value()},
                                {"utc_offset_hours", offset.has_value()}}) {
      if (!value && !s->get(field)) {
        r.Error(where, key, fmt::format("clock times need schedule.{} (and date, latitude_deg, longitude_deg, "
                                        "utc_offset_hours)", field));
        ok = false;
      }
    }
    return ok && latitude && longitude && offset;
  };
  if (latitude && longitude) schedule.place = GeoLocation{*latitude, *longitude};

  const int sources = int(s->contains("times")) + int(s->contains("sun")) + int(s->contains("frames"));
  if (sources != 1) {
    r.Error(s, "schedule",
            sources == 0 ? "no frames: give `times`, `sun` or [[schedule.frames]]"
                         : "give only one of `times`, `sun` and [[schedule.frames]]");
    return result;
  }

  std::vector<ScheduleFrame> frames;
  auto add_time_frame = [&](const toml::date& d, const toml::time& t, const toml::node* where) {
    ScheduleFrame f;
    f.time = MakeCivilTime(d, t, *offset);
    SolarPosition p = ComputeSolarPosition(*f.time, *schedule.place);
    f.elevation_deg = p.elevation_deg;
    f.azimuth_deg = p.azimuth_deg;
    f.sun_direction = p.direction;
    (void)where;
    frames.push_back(std::move(f));
  };

  if (const toml::node* times = s->get("times")) {
    const std::string key = "schedule.times";
    if (!date && !s->get("date")) r.Error(times, key, "clock times need schedule.date, e.g. date = 2013-05-27");
    bool place_ok = need_place(times, key);
    if (const toml::array* list = times->as_array()) {
      if (list->empty()) r.Error(times, key, "the list is empty");
      for (size_t i = 0; i < list->size(); ++i) {
        std::optional<toml::time> t = r.Time(list->get(i), fmt::format("{}[{}]", key, i));
        if (t && date && place_ok) add_time_frame(*date, *t, list->get(i));
      }
    } else if (const toml::table* range = times->as_table()) {
      r.CheckKeys(*range, key, {"start", "end", "step_minutes"});
      std::optional<toml::time> start = r.Time(range->get("start"), key + ".start");
      std::optional<toml::time> end = r.Time(range->get("end"), key + ".end");
      std::optional<double> step = r.Number(range->get("step_minutes"), key + ".step_minutes");
      if (!range->get("start") || !range->get("end") || !range->get("step_minutes"))
        r.Error(times, key, "a time range needs start, end and step_minutes, e.g. "
                            "{ start = 06:00:00, end = 20:00:00, step_minutes = 15 }");
      if (start && end && step) {
        auto seconds = [](const toml::time& t) { return t.hour * 3600.0 + t.minute * 60.0 + t.second + t.nanosecond * 1e-9; };
        double s0 = seconds(*start), s1 = seconds(*end);
        if (!(*step > 0.0)) {
          r.Error(range->get("step_minutes"), key + ".step_minutes", "must be above 0");
        } else if (s1 < s0) {
          r.Error(range->get("end"), key + ".end", "end is before start: a range stays within one day");
        } else if (std::optional<std::vector<double>> steps = r.Steps(times, key, s0, s1, *step * 60.0);
                   steps && date && place_ok) {
          for (double sec : *steps) {
            toml::time t;
            double whole = std::floor(sec + 1e-6);
            t.hour = uint8_t(int(whole) / 3600);
            t.minute = uint8_t((int(whole) % 3600) / 60);
            t.second = uint8_t(int(whole) % 60);
            t.nanosecond = uint32_t(std::max(0.0, sec - whole) * 1e9);
            add_time_frame(*date, t, times);
          }
        }
      }
    } else {
      r.Error(times, key, "expected a list of times or { start, end, step_minutes }");
    }
    schedule.clock_times = true;
  } else if (const toml::node* sun = s->get("sun")) {
    const std::string key = "schedule.sun";
    const toml::table* table = sun->as_table();
    if (!table) {
      r.Error(sun, key, "expected { elevation_deg = ..., azimuth_deg = ... }");
    } else {
      r.CheckKeys(*table, key, {"elevation_deg", "azimuth_deg"});
      std::optional<std::vector<double>> elevation = r.Series(table->get("elevation_deg"), key + ".elevation_deg");
      std::optional<std::vector<double>> azimuth = r.Series(table->get("azimuth_deg"), key + ".azimuth_deg");
      if (!table->get("elevation_deg") || !table->get("azimuth_deg"))
        r.Error(sun, key, "needs both elevation_deg and azimuth_deg (a number, a list or a range each)");
      if (elevation && azimuth) {
        size_t n = std::max(elevation->size(), azimuth->size());
        if (elevation->size() != n && elevation->size() != 1)
          r.Error(sun, key, fmt::format("elevation_deg has {} values and azimuth_deg {}: give equal counts, or one "
                                        "value for all", elevation->size(), azimuth->size()));
        else if (azimuth->size() != n && azimuth->size() != 1)
          r.Error(sun, key, fmt::format("azimuth_deg has {} values and elevation_deg {}: give equal counts, or one "
                                        "value for all", azimuth->size(), elevation->size()));
        else
          for (size_t i = 0; i < n; ++i) {
            ScheduleFrame f;
            f.elevation_deg = (*elevation)[elevation->size() == 1 ? 0 : i];
            f.azimuth_deg = (*azimuth)[azimuth->size() == 1 ? 0 : i];
            if (std::abs(f.elevation_deg) > 90.0) {
              r.Error(table->get("elevation_deg"), key + ".elevation_deg",
                      fmt::format("{} is out of range [-90, 90]", f.elevation_deg));
              break;
            }
            f.sun_direction = SunDirectionFromElevationAzimuth(f.elevation_deg, f.azimuth_deg);
            frames.push_back(std::move(f));
          }
      }
    }
  } else if (const toml::node* list = s->get("frames")) {
    const std::string key = "schedule.frames";
    const toml::array* array = list->as_array();
    if (!array || array->empty()) r.Error(list, key, "expected [[schedule.frames]] tables");
    bool any_time = false, all_time = true;
    for (size_t i = 0; array && i < array->size(); ++i) {
      const std::string fkey = fmt::format("{}[{}]", key, i);
      const toml::table* t = array->get(i)->as_table();
      if (!t) {
        r.Error(array->get(i), fkey, "expected a table");
        continue;
      }
      r.CheckKeys(*t, fkey, {"time", "date", "elevation_deg", "azimuth_deg", "set"});
      ScheduleFrame f;
      if (t->get("time")) {
        any_time = true;
        if (t->get("elevation_deg") || t->get("azimuth_deg"))
          r.Error(t, fkey, "give either time or elevation_deg/azimuth_deg, not both");
        std::optional<toml::time> tm = r.Time(t->get("time"), fkey + ".time");
        std::optional<toml::date> d = t->get("date") ? r.Date(t->get("date"), fkey + ".date") : date;
        if (!d) r.Error(t, fkey, "a clock time needs a date (schedule.date or the frame's date)");
        if (tm && d && need_place(t, fkey)) {
          add_time_frame(*d, *tm, t);
          f = frames.back();
          frames.pop_back();
        } else {
          continue;
        }
      } else {
        all_time = false;
        std::optional<double> e = r.Number(t->get("elevation_deg"), fkey + ".elevation_deg");
        std::optional<double> a = r.Number(t->get("azimuth_deg"), fkey + ".azimuth_deg");
        if (!t->get("elevation_deg") || !t->get("azimuth_deg")) {
          r.Error(t, fkey, "a frame needs time, or elevation_deg and azimuth_deg");
          continue;
        }
        if (!e || !a) continue;
        if (std::abs(*e) > 90.0) {
          r.Error(t->get("elevation_deg"), fkey + ".elevation_deg", fmt::format("{} is out of range [-90, 90]", *e));
          continue;
        }
        f.elevation_deg = *e;
        f.azimuth_deg = *a;
        f.sun_direction = SunDirectionFromElevationAzimuth(*e, *a);
      }
      if (const toml::node* set = t->get("set")) {
        if (const toml::table* st = set->as_table())
          r.Flatten(*st, "", f.overrides, fkey + ".set");
        else
          r.Error(set, fkey + ".set", "expected a table of style keys, e.g. set = { \"atmosphere.mie.g\" = 0.7 }");
      }
      frames.push_back(std::move(f));
    }
    schedule.clock_times = any_time && all_time;
    if (any_time && !all_time)
      r.Error(list, key, "mix of clock-time and elevation/azimuth frames: use one kind per schedule");
  }

  if (frames.size() > size_t(kMaxFrames))
    r.Error(s, "schedule", fmt::format("{} frames is more than the limit of {}", frames.size(), kMaxFrames));

  // Frame numbers, hours since the first frame, position along the schedule.
  for (size_t i = 0; i < frames.size(); ++i) {
    ScheduleFrame& f = frames[i];
    f.number = first_frame + int(i);
    if (schedule.clock_times) {
      // Whole days from the Julian days of the two midnights (exact in
      // double), then the clock difference, so that 15 minutes is 0.25 h exactly.
      auto midnight = [](CivilTime t) {
        t.hour = t.minute = 0;
        t.second = 0.0;
        return JulianDayUt(t) + t.utc_offset_hours / 24.0;
      };
      auto clock_hours = [](const CivilTime& t) {
        return t.hour + t.minute / 60.0 + t.second / 3600.0 - t.utc_offset_hours;
      };
      f.hours_from_start = std::round(midnight(*f.time) - midnight(*frames[0].time)) * 24.0 +
                           clock_hours(*f.time) - clock_hours(*frames[0].time);
    }
  }
  // Clock times run forward: the glTF sun animation's keys (hours) must
  // increase strictly, and a ramp by time needs an order.
  if (schedule.clock_times) {
    const char* list = s->get("times") ? "times" : "frames";
    for (size_t i = 1; i < frames.size(); ++i) {
      if (frames[i].hours_from_start > frames[i - 1].hours_from_start) continue;
      r.Error(s->get(list), std::string("schedule.") + list,
              fmt::format("frame {} ({}) is not after frame {} ({}): give clock times in increasing order, each "
                          "once", i + 1, frames[i].time->Iso8601(), i, frames[i - 1].time->Iso8601()));
      break;
    }
  }
  const double span_hours = frames.empty() ? 0.0 : frames.back().hours_from_start;
  for (size_t i = 0; i < frames.size(); ++i) {
    if (schedule.clock_times && span_hours != 0.0)
      frames[i].fraction = frames[i].hours_from_start / span_hours;
    else
      frames[i].fraction = frames.size() > 1 ? double(i) / double(frames.size() - 1) : 0.0;
  }
  schedule.frames = std::move(frames);

  // Per-frame changes of style keys.
  if (const toml::node* ramp = s->get("ramp")) {
    if (const toml::table* t = ramp->as_table()) {
      r.FlattenNumbers(*t, "", [&](const std::string& key, const toml::node& node) {
        const std::string where = "schedule.ramp." + key;
        const toml::array* pair = node.as_array();
        if (!pair || pair->size() != 2) {
          r.Error(&node, where, "expected [from, to]: two numbers, or two RGB triples");
          return;
        }
        std::optional<std::vector<double>> from = r.NumberOrTriple(*pair->get(0), where + "[0]");
        std::optional<std::vector<double>> to = r.NumberOrTriple(*pair->get(1), where + "[1]");
        if (!from || !to) return;
        if (from->size() != to->size()) {
          r.Error(&node, where, "from and to must both be numbers or both RGB triples");
          return;
        }
        schedule.ramps.push_back({key, *from, *to, r.Origin(&node, key)});
      }, "schedule.ramp");
    } else {
      r.Error(ramp, "schedule.ramp", "expected a table: \"style.key\" = [from, to]");
    }
  }
  if (const toml::node* per_hour = s->get("per_hour")) {
    if (const toml::table* t = per_hour->as_table()) {
      if (!schedule.clock_times && !t->empty())
        r.Error(per_hour, "schedule.per_hour", "rates per hour need clock-time frames (`times`)");
      r.FlattenNumbers(*t, "", [&](const std::string& key, const toml::node& node) {
        std::optional<std::vector<double>> rate = r.NumberOrTriple(node, "schedule.per_hour." + key);
        if (rate) schedule.rates.push_back({key, *rate, r.Origin(&node, key)});
      }, "schedule.per_hour");
    } else {
      r.Error(per_hour, "schedule.per_hour", "expected a table: \"style.key\" = rate");
    }
  }
  return result;
}

bool FileHasSchedule(const std::string& path) {
  std::string text;
  if (ReadInputFile(path, "style", text) || DeepKeyError(text, path)) return false;  // LoadSkyStyle reports it
  try {
    toml::table root = toml::parse(text, path);
    return root.contains("schedule");
  } catch (const toml::parse_error&) {
    return false;  // LoadSkyStyle reports the syntax error
  }
}

ScheduleResult LoadSchedule(const std::string& path) {
  std::string text;
  if (std::optional<ConfigError> e = ReadInputFile(path, "schedule", text)) {
    ScheduleResult result;
    result.errors.push_back(*e);
    return result;
  }
  return ParseSchedule(text, path);
}

std::vector<FrameOverride> FrameStyleOverrides(const Schedule& schedule, const ScheduleFrame& frame,
                                               const SkyStyle& base_style, std::vector<ConfigError>& errors) {
  std::vector<FrameOverride> out;
  FrameOverride sun_e, sun_a;
  sun_e.key = "sun.elevation_deg";
  sun_e.toml_value = FormatReal(frame.elevation_deg);
  sun_e.origin.file = schedule.source_path;
  sun_e.origin.key = sun_e.key;
  sun_a = sun_e;
  sun_a.key = sun_a.origin.key = "sun.azimuth_deg";
  sun_a.toml_value = FormatReal(frame.azimuth_deg);
  out.push_back(sun_e);
  out.push_back(sun_a);

  auto format_values = [](const std::vector<double>& v) {
    if (v.size() == 1) return FormatReal(v[0]);
    return fmt::format("[{}, {}, {}]", FormatReal(v[0]), FormatReal(v[1]), FormatReal(v[2]));
  };
  for (const ScheduleRamp& ramp : schedule.ramps) {
    std::vector<double> v(ramp.from.size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = ramp.from[i] + (ramp.to[i] - ramp.from[i]) * frame.fraction;
    out.push_back({ramp.key, format_values(v), ramp.origin});
  }
  if (!schedule.rates.empty()) {
    toml::table resolved;
    try {
      resolved = toml::parse(base_style.resolved_toml);
    } catch (const toml::parse_error&) {
    }
    for (const ScheduleRate& rate : schedule.rates) {
      const toml::node* base = resolved.at_path(rate.key).node();
      std::vector<double> v;
      if (base && base->is_number() && rate.rate_per_hour.size() == 1) {
        v.push_back(base->value<double>().value_or(0.0));
      } else if (base && base->is_array() && base->as_array()->size() == 3) {
        for (size_t i = 0; i < 3; ++i) v.push_back(base->as_array()->get(i)->value<double>().value_or(0.0));
      } else {
        ConfigError e = rate.origin;
        e.key = "schedule.per_hour." + rate.key;
        e.message = base ? "a triple rate needs an RGB-triple style key"
                         : fmt::format("'{}' is not a numeric style key (README lists them)", rate.key);
        errors.push_back(e);
        continue;
      }
      // A single rate applies to every channel of a triple.
      for (size_t i = 0; i < v.size(); ++i)
        v[i] += rate.rate_per_hour[rate.rate_per_hour.size() == 1 ? 0 : i] * frame.hours_from_start;
      out.push_back({rate.key, format_values(v), rate.origin});
    }
  }
  for (const FrameOverride& o : frame.overrides) out.push_back(o);
  return out;
}

FrameStyles ResolveFrameStyles(const std::string& style_path, const std::vector<std::string>& overrides,
                               const Schedule& schedule) {
  FrameStyles result;
  ConfigResult base = LoadSkyStyle(style_path, overrides);
  if (!base.ok()) {
    result.errors = base.errors;
    return result;
  }
  std::string text;
  if (std::optional<ConfigError> e = ReadInputFile(style_path, "style", text)) {
    result.errors.push_back(*e);
    return result;
  }
  for (const ScheduleFrame& frame : schedule.frames) {
    std::vector<ConfigError> errors;
    std::vector<FrameOverride> frame_overrides = FrameStyleOverrides(schedule, frame, base.style, errors);
    for (const FrameOverride& o : frame_overrides) {
      for (const std::string& set : overrides) {
        if (set.compare(0, o.key.size() + 1, o.key + "=") != 0) continue;
        if (std::any_of(result.warnings.begin(), result.warnings.end(),
                        [&](const ConfigError& w) { return w.key == o.key; }))
          continue;
        ConfigError w = o.origin;
        w.key = o.key;
        w.message = fmt::format("the schedule sets this key per frame, so --set {} has no effect on it", set);
        result.warnings.push_back(w);
      }
    }
    std::vector<std::string> all = overrides;
    for (const FrameOverride& o : frame_overrides) all.push_back(o.Assignment());
    ConfigResult styled = errors.empty() ? ParseSkyStyle(text, style_path, all) : ConfigResult{};
    for (ConfigError e : styled.errors) {
      // Errors from the frame's assignments point back into the schedule.
      for (const FrameOverride& o : frame_overrides) {
        if (e.key == o.key || e.key.rfind(o.key + "[", 0) == 0 || e.key.rfind(o.key + ".", 0) == 0) {
          e.file = o.origin.file;
          e.line = o.origin.line;
          e.column = o.origin.column;
          break;
        }
      }
      errors.push_back(e);
    }
    for (ConfigError& e : errors) e.message = fmt::format("frame {}: {}", frame.number, e.message);
    if (!errors.empty()) {
      // The same mistake in every frame is reported once.
      std::set<std::string> seen;
      for (const ConfigError& e : result.errors) seen.insert(e.file + e.key + std::to_string(e.line));
      for (ConfigError& e : errors)
        if (!seen.count(e.file + e.key + std::to_string(e.line))) result.errors.push_back(e);
      continue;
    }
    styled.style.source_path = style_path;
    result.styles.push_back(std::move(styled.style));
  }
  return result;
}

}  // namespace skybake
