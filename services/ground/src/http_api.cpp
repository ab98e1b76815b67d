#include "tetra/ground/http_api.hpp"

#include <filesystem>

#include "tetra/dds/topics.hpp"
#include "tetra/ground/encode.hpp"
#include "tetra/ground/record_files.hpp"
// After Eigen (through the headers above): httplib.h brings <resolv.h>, whose `_res` macro breaks Eigen.
#include <httplib.h>

namespace tetra::ground {

namespace {

using nlohmann::json;

//! The state of one browser's event stream between calls of the content provider.
struct StreamCursor {
  std::uint64_t after = 0;
  bool fresh = true;  //!< no Last-Event-ID: send the current state first
};

void append_message(std::string& out, const StreamMessage& m) {
  if (m.id != 0) out += "id: " + std::to_string(m.id) + '\n';
  out += "event: " + m.event + "\ndata: " + m.data + "\n\n";
}

std::uint64_t last_event_id(const httplib::Request& req) {
  std::string text = req.get_header_value("Last-Event-ID");
  if (text.empty()) text = req.get_param_value("last_event_id");
  if (text.empty()) return 0;
  try {
    return std::stoull(text);
  } catch (const std::exception&) {
    return 0;
  }
}

void reply_json(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");
  res.set_content(body.dump(), "application/json");
}

void reply_error(httplib::Response& res, int status, const std::string& message) {
  reply_json(res, status, {{"error", message}});
}

double number_param(const httplib::Request& req, const char* name, double fallback) {
  if (!req.has_param(name)) return fallback;
  try {
    return std::stod(req.get_param_value(name));
  } catch (const std::exception&) {
    return fallback;
  }
}

}  // namespace

GroundServer::GroundServer(GroundStore& store, SendCommand send, ServerConfig config)
    : store_(store),
      send_(std::move(send)),
      config_(std::move(config)),
      server_(std::make_unique<httplib::Server>()) {}

GroundServer::~GroundServer() {
  stop();
}

Status GroundServer::start() {
  const std::filesystem::path openmct = std::filesystem::path(config_.web_dir) / "node_modules/openmct/dist";
  if (!server_->set_mount_point("/", config_.web_dir)) {
    return bad_input("--web " + config_.web_dir + ": no such directory");
  }
  if (!server_->set_mount_point("/openmct", openmct.string())) {
    return failure(openmct.string() + " missing: run `npm ci` in " + config_.web_dir +
                   " (scripts/setup.sh does)");
  }
  const int threads = config_.worker_threads;
  server_->new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
  routes();
  port_ = config_.port == 0 ? server_->bind_to_any_port(config_.host)
                            : (server_->bind_to_port(config_.host, config_.port) ? config_.port : -1);
  if (port_ <= 0) {
    return failure("--listen " + config_.host + ":" + std::to_string(config_.port) + ": cannot bind");
  }
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  return ok_status();
}

void GroundServer::stop() {
  stopping_ = true;
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

void GroundServer::routes() {
  auto& s = *server_;
  s.Get("/api/units", [this](const httplib::Request&, httplib::Response& res) {
    reply_json(res, 200, store_.units_json(steady_now_ns()));
  });
  s.Get("/api/status", [this](const httplib::Request&, httplib::Response& res) {
    reply_json(res, 200,
               {{"last_event_id", store_.last_id()},
                {"stream_dropped", store_.stream_dropped()},
                {"units", store_.units_json(steady_now_ns())}});
  });
  s.Get("/api/history", [this](const httplib::Request& req, httplib::Response& res) {
    const auto max_points = static_cast<std::size_t>(number_param(req, "max", 5000));
    auto h = store_.history(req.get_param_value("unit"), req.get_param_value("kind"),
                            number_param(req, "start", 0), number_param(req, "end", 1e300), max_points);
    if (!h) return reply_error(res, 404, h.error().message);
    reply_json(res, 200, *h);
  });
  s.Get("/api/records", [this](const httplib::Request& req, httplib::Response& res) {
    if (config_.records_dir.empty()) return reply_error(res, 404, "no --records folder given");
    auto r = req.has_param("file")
                 ? read_record(config_.records_dir, req.get_param_value("file"),
                               number_param(req, "start", -1e300), number_param(req, "end", 1e300),
                               static_cast<std::size_t>(number_param(req, "max", 5000)))
                 : list_records(config_.records_dir);
    if (!r) return reply_error(res, 404, r.error().message);
    reply_json(res, 200, *r);
  });
  s.Get("/api/stream", [this](const httplib::Request& req, httplib::Response& res) {
    auto cursor = std::make_shared<StreamCursor>();
    cursor->after = last_event_id(req);
    cursor->fresh = cursor->after == 0;
    res.set_header("Cache-Control", "no-cache");
    res.set_header("X-Accel-Buffering", "no");  // nginx: pass events through unbuffered
    res.set_chunked_content_provider(
        "text/event-stream", [this, cursor](std::size_t, httplib::DataSink& sink) {
          if (stopping_) return false;
          std::string out;
          if (cursor->fresh) {
            cursor->fresh = false;
            cursor->after = store_.last_id();
            out += "retry: 1000\n\n";
            for (const auto& m : store_.snapshot(steady_now_ns())) append_message(out, m);
          }
          const StreamRead read =
              store_.read_stream(cursor->after, 512, std::chrono::milliseconds(config_.stream_wait_ms));
          if (read.gap) out += "event: reset\ndata: {}\n\n";  // the browser reloads history
          for (const auto& m : read.messages) {
            append_message(out, m);
            cursor->after = m.id;
          }
          if (out.empty()) out = ": keep-alive\n\n";
          return !stopping_ && sink.write(out.data(), out.size());
        });
  });
  s.Post("/api/command", [this](const httplib::Request& req, httplib::Response& res) {
    auto request = parse_command_request(req.body, "ground@" + req.remote_addr);
    if (!request) return reply_error(res, 400, request.error().message);
    auto ack = send_(*request);
    if (!ack) return reply_error(res, 504, ack.error().message);
    reply_json(res, 200, ack_json(*ack, 16));
  });
}

}  // namespace tetra::ground
