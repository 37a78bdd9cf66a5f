#include <dicestack/pages/page.hpp>

#include <cctype>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/pages/resources.hpp>
#include <dicestack/version.hpp>

namespace dicestack {
namespace fs = std::filesystem;
using nlohmann::json;

namespace page {

std::string table_page_html(const std::string& data_json, const char* script) {
  std::string html;
  html += "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<meta name=\"generator\" content=\"dicestack " DICESTACK_VERSION "\">\n";
  html += "<title>dicestack results</title>\n<style>";
  html += resource::table_css;
  html += "</style>\n</head>\n<body>\n<h1 id=\"title\"></h1>\n<p id=\"header\"></p>\n<dl id=\"facts\"></dl>\n";
  html += "<table id=\"board\"><thead><tr></tr></thead><tbody></tbody></table>\n";
  html += "<noscript>This page builds its table with JavaScript; the same rows are in the JSON below.</noscript>\n";
  html += "<script type=\"application/json\" id=\"page-data\">";
  html += script_safe(data_json);
  html += "</script>\n<script>";
  html += resource::table_js;
  html += script;
  html += "</script>\n</body>\n</html>\n";
  return html;
}

// JSON that may sit inside <script>: no "<", ">" or "&" (only strings can hold them; \u escapes
// read back the same).
std::string script_safe(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<') out += "\\u003c";
    else if (c == '>') out += "\\u003e";
    else if (c == '&') out += "\\u0026";
    else out += c;
  }
  return out;
}

std::string url_segment(const std::string& name) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : name) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

bool is_marked_folder(const fs::path& folder, const char* marker, const char* format) {
  std::error_code ec;
  if (fs::symlink_status(folder, ec).type() != fs::file_type::directory) return false;
  return Ownership::json_object("", format).recognises(folder / marker);
}

void check_marked_folder(const fs::path& folder, const char* marker, const char* format, const std::string& what) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(folder, ec);
  if (!fs::exists(st)) return;
  if (fs::is_symlink(st))
    throw InputError(folder.string() + ": is a symbolic link; refusing to replace it with a " + what);
  if (is_marked_folder(folder, marker, format)) return;
  throw InputError(folder.string() + ": exists and is not a " + what +
                   " dicestack wrote; refusing to replace it: choose another --out or remove it yourself");
}

void write_marker(const fs::path& file, const char* format, int version) {
  AtomicFile f(file, Ownership::json_object("", format), AtomicFile::Leftovers::skip);
  f.stream() << json{{"format", format}, {"version", version}, {"dicestack_version", DICESTACK_VERSION}}.dump(2) << '\n';
  f.commit();
}

}  // namespace page

std::filesystem::path page_media_folder(const fs::path& page) {
  return page.parent_path() / (page.stem().string() + "_files");
}

Ownership results_page_ownership() { return Ownership::first_line("dicestack results page", {kResultsPageMarker}); }

}  // namespace dicestack
