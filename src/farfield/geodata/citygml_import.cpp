// CityGML import. libcitygml parses the document (Xerces-C) into city objects, geometries and polygons with their
// appearances; it is asked not to tessellate, so that every polygon is triangulated here, in its plane and with its
// holes, like CityJSON faces (its own tessellator keeps a ring's closing vertex and makes a degenerate triangle of
// it). Two passes: the first chooses each object's LoD and polygons and bounds them (the origin is the centre of
// those bounds), the second triangulates them in local coordinates. libcitygml reports a malformed document by
// throwing Xerces exceptions (not std::exception) or by returning no model: both become farfield::Error here.
// Here: the entry points, parsing and the CRS; citygml_importer.h lists the files of the two passes.
#include "farfield/geodata/citygml_import.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <citygml/citygml.h>
#include <citygml/citygmllogger.h>
#include <citygml/citymodel.h>
#include <citygml/cityobject.h>
#include <citygml/envelope.h>
#include <citygml/geometry.h>
#include <citygml/polygon.h>
#include <proj.h>
#include <xercesc/sax/SAXParseException.hpp>
#include <xercesc/util/XMLException.hpp>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/timer.h"
#include "farfield/geodata/citygml_importer.h"

namespace farfield::geodata {

namespace citygml_import {

namespace {

// True when PROJ reads `srs` as a geographic CRS (degrees), alone or as the horizontal part of a compound one.
bool isGeographic(const std::string& srs) {
  if (srs.empty()) return false;
  PJ_CONTEXT* ctx = proj_context_create();
  proj_log_level(ctx, PJ_LOG_NONE);
  bool geographic = false;
  if (PJ* crs = proj_create(ctx, srs.c_str())) {
    PJ_TYPE type = proj_get_type(crs);
    PJ* horizontal = nullptr;
    if (type == PJ_TYPE_COMPOUND_CRS && (horizontal = proj_crs_get_sub_crs(ctx, crs, 0)))
      type = proj_get_type(horizontal);
    geographic = type == PJ_TYPE_GEOGRAPHIC_2D_CRS || type == PJ_TYPE_GEOGRAPHIC_3D_CRS;
    if (horizontal) proj_destroy(horizontal);
    proj_destroy(crs);
  }
  proj_context_destroy(ctx);
  return geographic;
}

}  // namespace

void Importer::run(const citygml::CityModel& model) {
  Stopwatch clock;
  st_.themes = model.themes();
  if (!options_.theme.empty() && std::find(st_.themes.begin(), st_.themes.end(), options_.theme) == st_.themes.end()) {
    std::string known;
    for (const std::string& t : st_.themes) known += (known.empty() ? "" : ", ") + t;
    throw Error(source_,
                "no appearance theme '" + options_.theme + "' (themes: " + (known.empty() ? "none" : known) + ")");
  }
  st_.theme = !options_.theme.empty() ? options_.theme : st_.themes.empty() ? std::string() : st_.themes.front();

  const citygml::ConstCityObjects roots = model.getRootCityObjects();
  st_.city_objects = roots.size();
  for (const citygml::CityObject* o : roots) chooseSurfaces(*o);
  readCrs(model);

  // Bounds of what is drawn (exterior rings), in file coordinates; the origin is their rounded centre.
  DVec3 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
  for (const Unit& u : units_)
    for (const Surface& s : u.surfaces)
      if (const auto ring = s.polygon->exteriorRing())
        for (const TVec3d& v : ring->getVertices()) {
          const DVec3 p(v.x, v.y, v.z);
          if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
          lo = glm::min(lo, p);
          hi = glm::max(hi, p);
        }
  if (lo.x > hi.x) throw noSurface();
  origin_ = DVec3(std::round(0.5 * (lo.x + hi.x)), std::round(0.5 * (lo.y + hi.y)), 0.0);
  result_.reference.origin = origin_;
  st_.read_s += clock.seconds();
  clock.restart();

  build();
  st_.build_s = clock.seconds();
}

Error Importer::noSurface() const {
  std::string why;
  for (const auto& [reason, n] : st_.skipped) why += (why.empty() ? "" : ", ") + std::to_string(n) + " " + reason;
  return Error(source_, "no usable surface in " + std::to_string(st_.city_objects) + " city objects" +
                            (why.empty() ? std::string() : " (skipped: " + why + ")"));
}

void Importer::readCrs(const citygml::CityModel& model) {
  std::string srs = model.getEnvelope().srsName();
  if (srs.empty()) srs = model.getSRSName();
  for (size_t i = 0; srs.empty() && i < units_.size(); ++i)
    for (unsigned g = 0; srs.empty() && g < units_[i].object->getGeometriesCount(); ++g)
      srs = units_[i].object->getGeometry(g).getSRSName();
  st_.crs = srs;
  result_.reference.crs = srs.empty() ? "unknown (CityGML without srsName)" : srs;
  result_.reference.description = srs;
  if (isGeographic(srs))
    throw Error(source_, "geographic coordinates (" + srs +
                             ", degrees) are not supported: reproject the file to a projected CRS in metres first");
}

}  // namespace citygml_import

namespace {

using namespace citygml_import;

// Xerces messages are UTF-16; the ASCII part is what an error message needs.
std::string narrow(const XMLCh* s) {
  std::string out;
  for (; s && *s; ++s) out += (*s < 128) ? char(*s) : '?';
  return out;
}

// libcitygml's log: errors and warnings counted, the first error kept for the message of a failed load.
class Logger final : public citygml::CityGMLLogger {
 public:
  Logger() : CityGMLLogger(LOGLEVEL::LL_WARNING) {}
  void log(LOGLEVEL level, const std::string& message, const char*, int) const override {
    if (level == LOGLEVEL::LL_ERROR && first_error.empty()) first_error = message;
    ++count;
    FF_DEBUG("libcitygml: " << message);
  }
  mutable std::string first_error;
  mutable size_t count = 0;
};

// "2.0" or "1.0" from the CityGML namespace declared at the top of the document.
std::string versionOf(const std::string& head) {
  if (head.find("opengis.net/citygml/2.0") != std::string::npos) return "2.0";
  if (head.find("opengis.net/citygml/1.0") != std::string::npos) return "1.0";
  if (head.find("opengis.net/citygml/3.0") != std::string::npos) return "3.0";
  return "";
}

// Parses with libcitygml (from a file or a stream); every way it reports failure becomes an Error naming `source`.
template <class Load>
std::shared_ptr<const citygml::CityModel> parse(const std::string& source, Load&& load) {
  auto logger = std::make_shared<Logger>();
  std::shared_ptr<const citygml::CityModel> model;
  try {
    model = load(logger);
  } catch (const xercesc::SAXParseException& e) {
    throw Error(source, "line " + std::to_string(e.getLineNumber()) + ", column " +
                            std::to_string(e.getColumnNumber()) +
                            ": not well-formed XML (truncated or corrupt file?): " + narrow(e.getMessage()));
  } catch (const xercesc::XMLException& e) {
    throw Error(source, "cannot read XML: " + narrow(e.getMessage()));
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(source, std::string("cannot read CityGML: ") + e.what());
  } catch (...) {
    throw Error(source, "cannot read CityGML (the parser failed without a message)");
  }
  if (!model)
    throw Error(source, "no CityGML CityModel in the document" +
                            (logger->first_error.empty() ? std::string() : " (" + logger->first_error + ")"));
  return model;
}

citygml::ParserParams parserParams() {
  citygml::ParserParams params;
  params.tesselate = false;  // triangulated here (see the file comment)
  params.optimize = false;
  params.pruneEmptyObjects = false;
  return params;
}

CityGmlScene importModel(const citygml::CityModel& model, const std::string& source, const std::string& base_dir,
                         const std::string& version, double read_s, const CityGmlImportOptions& options) {
  CityGmlScene result;
  result.stats.version = version;
  result.stats.read_s = read_s;
  Importer(source, base_dir, options, result).run(model);
  return result;
}

void checkVersion(const std::string& source, const std::string& version) {
  if (version == "3.0") throw Error(source, "CityGML 3.0 is not supported (supported: 1.0, 2.0)");
}

}  // namespace

size_t CityGmlStats::skippedTotal() const {
  size_t n = 0;
  for (const auto& [reason, count] : skipped) n += count;
  return n;
}

CityGmlScene importCityGml(const std::string& path, const CityGmlImportOptions& options) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path, "file not found");
  if (!fs::is_regular_file(path, ec)) throw Error(path, "not a regular file");
  std::string head(65536, '\0');
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, "cannot open file");
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(size_t(in.gcount()));
  }
  if (head.empty()) throw Error(path, "empty file");
  const std::string version = versionOf(head);
  checkVersion(path, version);
  Stopwatch clock;
  const auto model = parse(path, [&](std::shared_ptr<Logger> logger) {
    return citygml::load(path, parserParams(), logger);
  });
  return importModel(*model, path, fs::path(path).parent_path().string(), version, clock.seconds(), options);
}

CityGmlScene importCityGmlText(const std::string& text, const std::string& source, const std::string& base_dir,
                               const CityGmlImportOptions& options) {
  if (text.empty()) throw Error(source, "empty document");
  const std::string version = versionOf(text.substr(0, 65536));
  checkVersion(source, version);
  Stopwatch clock;
  const auto model = parse(source, [&](std::shared_ptr<Logger> logger) {
    std::istringstream in(text);
    return citygml::load(in, parserParams(), logger);
  });
  return importModel(*model, source, base_dir, version, clock.seconds(), options);
}

}  // namespace farfield::geodata
