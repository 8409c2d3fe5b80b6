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
  std::optional<std::vector<double>> Steps(const toml::node* node, const std::string& key, double start, double end,
                                           double step) {
    if (step == 0.0 || (end - start) * step < 0.0) {
      Error(node, key,
            fmt::format("step {} cannot go from {} to {}: use a non-zero step with the sign of end - start", step,
                        start, end));
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
    if (!ok) {
      Error(&node, where, fmt::format("'{}' is not a style key: use a dotted key such as \"atmosphere.mie.g\"", key));
    } else if (KeyHasTooManyParts(key)) {
      // Refused here, once, before any frame's style splits it at the dots.
      Error(&node, where.substr(0, where.size() - key.size()) + key.substr(0, key.find('.')) + ".(...)",
            fmt::format("a style key of more than {} dotted parts: skybake's keys have at most 5, e.g. "
                        "\"atmosphere.mie.g\"",
                        kMaxKeyParts));
      ok = false;
    }
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

namespace {

// One [schedule] table read into its frames: where and when, the frames of
// its one source (times, sun or [[schedule.frames]]), their numbers, hours
// and places along the schedule, and the per-frame changes of style keys.
class ScheduleParser {
 public:
  ScheduleParser(ScheduleReader& r, const toml::table& s, Schedule& schedule) : r_(r), s_(s), schedule_(schedule) {}

  int FirstFrame() {
    int first_frame = 1;
    if (const toml::node* n = s_.get("first_frame")) {
      if (!n->is_integer() || n->as_integer()->get() < 1 || n->as_integer()->get() > 9999999)
        r_.Error(n, "schedule.first_frame", "expected an integer in [1, 9999999]");
      else first_frame = int(n->as_integer()->get());
    }
    return first_frame;
  }

  // Where and when, for clock times.
  void ReadPlace() {
    date_ = r_.Date(s_.get("date"), "schedule.date");
    latitude_ = r_.Number(s_.get("latitude_deg"), "schedule.latitude_deg");
    longitude_ = r_.Number(s_.get("longitude_deg"), "schedule.longitude_deg");
    offset_ = r_.Number(s_.get("utc_offset_hours"), "schedule.utc_offset_hours");
    if (latitude_ && std::abs(*latitude_) > 90.0)
      r_.Error(s_.get("latitude_deg"), "schedule.latitude_deg", "latitude must be within [-90, 90]");
    if (longitude_ && std::abs(*longitude_) > 180.0)
      r_.Error(s_.get("longitude_deg"), "schedule.longitude_deg",
               "longitude must be within [-180, 180], east positive");
    if (offset_ && std::abs(*offset_) > 14.0)
      r_.Error(s_.get("utc_offset_hours"), "schedule.utc_offset_hours", "UTC offset must be within [-14, 14] hours");
    if (date_ && (date_->month < 1 || date_->month > 12 || date_->day < 1 ||
                  date_->day > DaysInMonth(date_->year, date_->month)))
      r_.Error(s_.get("date"), "schedule.date", "not a calendar date");
    if (latitude_ && longitude_) schedule_.place = GeoLocation{*latitude_, *longitude_};
  }

  // `times`: a list of clock times, or { start, end, step_minutes }.
  void ReadTimes(const toml::node& times) {
    const std::string key = "schedule.times";
    if (!date_ && !s_.get("date")) r_.Error(&times, key, "clock times need schedule.date, e.g. date = 2013-05-27");
    bool place_ok = NeedPlace(&times, key);
    if (const toml::array* list = times.as_array()) {
      if (list->empty()) r_.Error(&times, key, "the list is empty");
      for (size_t i = 0; i < list->size(); ++i) {
        std::optional<toml::time> t = r_.Time(list->get(i), fmt::format("{}[{}]", key, i));
        if (t && date_ && place_ok) frames_.push_back(TimeFrame(*date_, *t));
      }
    } else if (const toml::table* range = times.as_table()) {
      ReadTimeRange(times, *range, key, place_ok);
    } else {
      r_.Error(&times, key, "expected a list of times or { start, end, step_minutes }");
    }
    schedule_.clock_times = true;
  }

  // `sun`: elevation_deg and azimuth_deg, each a number, a list or a range.
  void ReadSun(const toml::node& sun) {
    const std::string key = "schedule.sun";
    const toml::table* table = sun.as_table();
    if (!table) {
      r_.Error(&sun, key, "expected { elevation_deg = ..., azimuth_deg = ... }");
      return;
    }
    r_.CheckKeys(*table, key, {"elevation_deg", "azimuth_deg"});
    std::optional<std::vector<double>> elevation = r_.Series(table->get("elevation_deg"), key + ".elevation_deg");
    std::optional<std::vector<double>> azimuth = r_.Series(table->get("azimuth_deg"), key + ".azimuth_deg");
    if (!table->get("elevation_deg") || !table->get("azimuth_deg"))
      r_.Error(&sun, key, "needs both elevation_deg and azimuth_deg (a number, a list or a range each)");
    if (!elevation || !azimuth) return;
    size_t n = std::max(elevation->size(), azimuth->size());
    if (elevation->size() != n && elevation->size() != 1) {
      r_.Error(&sun, key,
               fmt::format("elevation_deg has {} values and azimuth_deg {}: give equal counts, or one "
                           "value for all",
                           elevation->size(), azimuth->size()));
      return;
    }
    if (azimuth->size() != n && azimuth->size() != 1) {
      r_.Error(&sun, key,
               fmt::format("azimuth_deg has {} values and elevation_deg {}: give equal counts, or one "
                           "value for all",
                           azimuth->size(), elevation->size()));
      return;
    }
    for (size_t i = 0; i < n; ++i) {
      ScheduleFrame f;
      f.elevation_deg = (*elevation)[elevation->size() == 1 ? 0 : i];
      f.azimuth_deg = (*azimuth)[azimuth->size() == 1 ? 0 : i];
      if (std::abs(f.elevation_deg) > 90.0) {
        r_.Error(table->get("elevation_deg"), key + ".elevation_deg",
                 fmt::format("{} is out of range [-90, 90]", f.elevation_deg));
        break;
      }
      f.sun_direction = SunDirectionFromElevationAzimuth(f.elevation_deg, f.azimuth_deg);
      frames_.push_back(std::move(f));
    }
  }

  // [[schedule.frames]]: each a clock time or a sun position, with its
  // style changes; one kind per schedule.
  void ReadFrameList(const toml::node& list) {
    const std::string key = "schedule.frames";
    const toml::array* array = list.as_array();
    if (!array || array->empty()) r_.Error(&list, key, "expected [[schedule.frames]] tables");
    bool any_time = false, all_time = true;
    for (size_t i = 0; array && i < array->size(); ++i) {
      const std::string fkey = fmt::format("{}[{}]", key, i);
      const toml::table* t = array->get(i)->as_table();
      if (!t) {
        r_.Error(array->get(i), fkey, "expected a table");
        continue;
      }
      r_.CheckKeys(*t, fkey, {"time", "date", "elevation_deg", "azimuth_deg", "set"});
      if (t->get("time")) any_time = true;
      else all_time = false;
      std::optional<ScheduleFrame> f = t->get("time") ? ListedTimeFrame(*t, fkey) : ListedSunFrame(*t, fkey);
      if (!f) continue;
      if (const toml::node* set = t->get("set")) {
        if (const toml::table* st = set->as_table()) r_.Flatten(*st, "", f->overrides, fkey + ".set");
        else r_.Error(set, fkey + ".set", "expected a table of style keys, e.g. set = { \"atmosphere.mie.g\" = 0.7 }");
      }
      frames_.push_back(std::move(*f));
    }
    schedule_.clock_times = any_time && all_time;
    if (any_time && !all_time)
      r_.Error(&list, key, "mix of clock-time and elevation/azimuth frames: use one kind per schedule");
  }

  // Frame numbers, hours since the first frame, position along the schedule.
  void NumberFrames(int first_frame) {
    std::vector<ScheduleFrame>& frames = frames_;
    if (frames.size() > size_t(kMaxFrames))
      r_.Error(&s_, "schedule", fmt::format("{} frames is more than the limit of {}", frames.size(), kMaxFrames));
    for (size_t i = 0; i < frames.size(); ++i) {
      ScheduleFrame& f = frames[i];
      f.number = first_frame + int(i);
      if (schedule_.clock_times) f.hours_from_start = HoursBetween(*frames[0].time, *f.time);
    }
    // Clock times run forward: the glTF sun animation's keys (hours) must
    // increase strictly, and a ramp by time needs an order.
    if (schedule_.clock_times) {
      const char* list = s_.get("times") ? "times" : "frames";
      for (size_t i = 1; i < frames.size(); ++i) {
        if (frames[i].hours_from_start > frames[i - 1].hours_from_start) continue;
        r_.Error(s_.get(list), std::string("schedule.") + list,
                 fmt::format("frame {} ({}) is not after frame {} ({}): give clock times in increasing order, each "
                             "once",
                             i + 1, frames[i].time->Iso8601(), i, frames[i - 1].time->Iso8601()));
        break;
      }
    }
    const double span_hours = frames.empty() ? 0.0 : frames.back().hours_from_start;
    for (size_t i = 0; i < frames.size(); ++i) {
      if (schedule_.clock_times && span_hours != 0.0) frames[i].fraction = frames[i].hours_from_start / span_hours;
      else frames[i].fraction = frames.size() > 1 ? double(i) / double(frames.size() - 1) : 0.0;
    }
    schedule_.frames = std::move(frames);
  }

  // `ramp`: "style.key" = [from, to], numbers or RGB triples.
  void ReadRamps() {
    const toml::node* ramp = s_.get("ramp");
    if (!ramp) return;
    const toml::table* t = ramp->as_table();
    if (!t) {
      r_.Error(ramp, "schedule.ramp", "expected a table: \"style.key\" = [from, to]");
      return;
    }
    r_.FlattenNumbers(
        *t, "",
        [&](const std::string& key, const toml::node& node) {
          const std::string where = "schedule.ramp." + key;
          const toml::array* pair = node.as_array();
          if (!pair || pair->size() != 2) {
            r_.Error(&node, where, "expected [from, to]: two numbers, or two RGB triples");
            return;
          }
          std::optional<std::vector<double>> from = r_.NumberOrTriple(*pair->get(0), where + "[0]");
          std::optional<std::vector<double>> to = r_.NumberOrTriple(*pair->get(1), where + "[1]");
          if (!from || !to) return;
          if (from->size() != to->size()) {
            r_.Error(&node, where, "from and to must both be numbers or both RGB triples");
            return;
          }
          schedule_.ramps.push_back({key, *from, *to, r_.Origin(&node, key)});
        },
        "schedule.ramp");
  }

  // `per_hour`: "style.key" = rate, for clock-time frames.
  void ReadRates() {
    const toml::node* per_hour = s_.get("per_hour");
    if (!per_hour) return;
    const toml::table* t = per_hour->as_table();
    if (!t) {
      r_.Error(per_hour, "schedule.per_hour", "expected a table: \"style.key\" = rate");
      return;
    }
    if (!schedule_.clock_times && !t->empty())
      r_.Error(per_hour, "schedule.per_hour", "rates per hour need clock-time frames (`times`)");
    r_.FlattenNumbers(
        *t, "",
        [&](const std::string& key, const toml::node& node) {
          std::optional<std::vector<double>> rate = r_.NumberOrTriple(node, "schedule.per_hour." + key);
          if (rate) schedule_.rates.push_back({key, *rate, r_.Origin(&node, key)});
        },
        "schedule.per_hour");
  }

 private:
  // Whether the place and offset that clock times need are given (each
  // missing one reported at `where`).
  bool NeedPlace(const toml::node* where, const std::string& key) {
    bool ok = true;
    for (auto [field, value] : {std::pair{"latitude_deg", latitude_.has_value()},
                                {"longitude_deg", longitude_.has_value()},
                                {"utc_offset_hours", offset_.has_value()}}) {
      if (!value && !s_.get(field)) {
        r_.Error(where, key,
                 fmt::format("clock times need schedule.{} (and date, latitude_deg, longitude_deg, "
                             "utc_offset_hours)",
                             field));
        ok = false;
      }
    }
    return ok && latitude_ && longitude_ && offset_;
  }

  // The frame at a clock time: the Sun from the place (NeedPlace).
  ScheduleFrame TimeFrame(const toml::date& d, const toml::time& t) const {
    ScheduleFrame f;
    f.time = MakeCivilTime(d, t, *offset_);
    SolarPosition p = ComputeSolarPosition(*f.time, *schedule_.place);
    f.elevation_deg = p.elevation_deg;
    f.azimuth_deg = p.azimuth_deg;
    f.sun_direction = p.direction;
    return f;
  }

  void ReadTimeRange(const toml::node& times, const toml::table& range, const std::string& key, bool place_ok) {
    r_.CheckKeys(range, key, {"start", "end", "step_minutes"});
    std::optional<toml::time> start = r_.Time(range.get("start"), key + ".start");
    std::optional<toml::time> end = r_.Time(range.get("end"), key + ".end");
    std::optional<double> step = r_.Number(range.get("step_minutes"), key + ".step_minutes");
    if (!range.get("start") || !range.get("end") || !range.get("step_minutes"))
      r_.Error(&times, key,
               "a time range needs start, end and step_minutes, e.g. "
               "{ start = 06:00:00, end = 20:00:00, step_minutes = 15 }");
    if (!start || !end || !step) return;
    auto seconds = [](const toml::time& t) {
      return t.hour * 3600.0 + t.minute * 60.0 + t.second + t.nanosecond * 1e-9;
    };
    double s0 = seconds(*start), s1 = seconds(*end);
    if (!(*step > 0.0)) {
      r_.Error(range.get("step_minutes"), key + ".step_minutes", "must be above 0");
    } else if (s1 < s0) {
      r_.Error(range.get("end"), key + ".end", "end is before start: a range stays within one day");
    } else if (std::optional<std::vector<double>> steps = r_.Steps(&times, key, s0, s1, *step * 60.0);
               steps && date_ && place_ok) {
      for (double sec : *steps) {
        toml::time t;
        double whole = std::floor(sec + 1e-6);
        t.hour = uint8_t(int(whole) / 3600);
        t.minute = uint8_t((int(whole) % 3600) / 60);
        t.second = uint8_t(int(whole) % 60);
        t.nanosecond = uint32_t(std::max(0.0, sec - whole) * 1e9);
        frames_.push_back(TimeFrame(*date_, t));
      }
    }
  }

  // A [[schedule.frames]] entry with a clock time (and its own date or the schedule's).
  std::optional<ScheduleFrame> ListedTimeFrame(const toml::table& t, const std::string& fkey) {
    if (t.get("elevation_deg") || t.get("azimuth_deg"))
      r_.Error(&t, fkey, "give either time or elevation_deg/azimuth_deg, not both");
    std::optional<toml::time> tm = r_.Time(t.get("time"), fkey + ".time");
    std::optional<toml::date> d = t.get("date") ? r_.Date(t.get("date"), fkey + ".date") : date_;
    if (!d) r_.Error(&t, fkey, "a clock time needs a date (schedule.date or the frame's date)");
    if (tm && d && NeedPlace(&t, fkey)) return TimeFrame(*d, *tm);
    return std::nullopt;
  }

  // A [[schedule.frames]] entry with the Sun's elevation and azimuth.
  std::optional<ScheduleFrame> ListedSunFrame(const toml::table& t, const std::string& fkey) {
    std::optional<double> e = r_.Number(t.get("elevation_deg"), fkey + ".elevation_deg");
    std::optional<double> a = r_.Number(t.get("azimuth_deg"), fkey + ".azimuth_deg");
    if (!t.get("elevation_deg") || !t.get("azimuth_deg")) {
      r_.Error(&t, fkey, "a frame needs time, or elevation_deg and azimuth_deg");
      return std::nullopt;
    }
    if (!e || !a) return std::nullopt;
    if (std::abs(*e) > 90.0) {
      r_.Error(t.get("elevation_deg"), fkey + ".elevation_deg", fmt::format("{} is out of range [-90, 90]", *e));
      return std::nullopt;
    }
    ScheduleFrame f;
    f.elevation_deg = *e;
    f.azimuth_deg = *a;
    f.sun_direction = SunDirectionFromElevationAzimuth(*e, *a);
    return f;
  }

  // Hours of clock time from `first` to `t`: whole days from the Julian
  // days of the two midnights (exact in double), then the clock difference,
  // so that 15 minutes is 0.25 h exactly.
  static double HoursBetween(const CivilTime& first, const CivilTime& t) {
    auto midnight = [](CivilTime c) {
      c.hour = c.minute = 0;
      c.second = 0.0;
      return JulianDayUt(c) + c.utc_offset_hours / 24.0;
    };
    auto clock_hours = [](const CivilTime& c) {
      return c.hour + c.minute / 60.0 + c.second / 3600.0 - c.utc_offset_hours;
    };
    return std::round(midnight(t) - midnight(first)) * 24.0 + clock_hours(t) - clock_hours(first);
  }

  ScheduleReader& r_;
  const toml::table& s_;
  Schedule& schedule_;
  std::optional<toml::date> date_;
  std::optional<double> latitude_, longitude_, offset_;
  std::vector<ScheduleFrame> frames_;
};

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
              {"first_frame", "date", "latitude_deg", "longitude_deg", "utc_offset_hours", "times", "sun", "frames",
               "ramp", "per_hour"});
  ScheduleParser parser(r, *s, schedule);
  const int first_frame = parser.FirstFrame();
  parser.ReadPlace();

  // The frames, from exactly one source.
  const int sources = int(s->contains("times")) + int(s->contains("sun")) + int(s->contains("frames"));
  if (sources != 1) {
    r.Error(s, "schedule",
            sources == 0 ? "no frames: give `times`, `sun` or [[schedule.frames]]"
                         : "give only one of `times`, `sun` and [[schedule.frames]]");
    return result;
  }
  if (const toml::node* times = s->get("times")) parser.ReadTimes(*times);
  else if (const toml::node* sun = s->get("sun")) parser.ReadSun(*sun);
  else if (const toml::node* list = s->get("frames")) parser.ReadFrameList(*list);
  parser.NumberFrames(first_frame);

  // Per-frame changes of style keys.
  parser.ReadRamps();
  parser.ReadRates();
  return result;
}

bool FileHasSchedule(const std::string& path) {
  std::string text;
  if (ReadInputFile(path, "style", text)) return false;  // LoadSkyStyle reports it
  return TextHasSchedule(text, path);
}

bool TextHasSchedule(std::string_view toml_text, const std::string& name) {
  if (DeepKeyError(toml_text, name)) return false;  // the style reader reports it
  try {
    toml::table root = toml::parse(toml_text, name);
    return root.contains("schedule");
  } catch (const toml::parse_error&) {
    return false;  // the style reader reports the syntax error
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
  std::string text;
  if (std::optional<ConfigError> e = ReadInputFile(style_path, "style", text)) {
    FrameStyles result;
    result.errors.push_back(*e);
    return result;
  }
  return ResolveFrameStylesOfText(text, style_path, overrides, schedule);
}

FrameStyles ResolveFrameStylesOfText(std::string_view text, const std::string& style_path,
                                     const std::vector<std::string>& overrides, const Schedule& schedule) {
  FrameStyles result;
  ConfigResult base = ParseSkyStyle(text, style_path, overrides);
  if (!base.ok()) {
    result.errors = base.errors;
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
    ConfigResult styled;
    if (errors.empty()) styled = ParseSkyStyle(text, style_path, all);
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
    // The formation's clock (cloud_formation.h): the frame's local clock time.
    if (frame.time)
      styled.style.clouds.local_clock_s = frame.time->hour * 3600.0 + frame.time->minute * 60.0 + frame.time->second;
    result.styles.push_back(std::move(styled.style));
  }
  return result;
}

}  // namespace skybake
