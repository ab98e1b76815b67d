#include "tetra/report/ledger_explainer.hpp"

#include "tetra/core/csv.hpp"
#include "tetra/report/text.hpp"

namespace tetra::report {

bool is_decision(fdi::EventType type) {
  return type == fdi::EventType::kDetected || type == fdi::EventType::kIsolated ||
         type == fdi::EventType::kUnisolated || type == fdi::EventType::kCleared ||
         type == fdi::EventType::kReferenceRejected || type == fdi::EventType::kReferenceAccepted ||
         type == fdi::EventType::kCalibrationMismatch;
}

LedgerExplainer::LedgerExplainer(double at_s, std::size_t decisions_kept)
    : at_s_(at_s), kept_(decisions_kept) {}

void LedgerExplainer::observe(double time_s, const fdi::StepResult& step, const fdi::Pipeline& pipeline) {
  if (time_s > at_s_) return;
  for (const auto& e : step.events) {
    if (!is_decision(e.type)) continue;
    decisions_.push_back({time_s, e});
    if (decisions_.size() > kept_) decisions_.pop_front();
  }
  if (step.accepted) {
    health_ = pipeline.health();
    health_time_s_ = time_s;
  }
}

namespace {

std::string headline(const fdi::FdiEvent& e) {
  std::string s = fdi::to_string(e.type);
  if (e.gyro) s += " gyro " + std::to_string(*e.gyro);
  if (e.type == fdi::EventType::kIsolated) {
    s += std::string(" (") + fdi::to_string(e.kind) + ", evidence " + fdi::to_string(e.evidence) + ")";
    const int ruling = fdi::ruling_of(e);
    s += ruling == e.gyro.value_or(0) ? ": the rule holds on these rows"
                                      : ": the rule does not name this gyro on these rows";
  } else if (e.type == fdi::EventType::kDetected || e.type == fdi::EventType::kUnisolated) {
    s += std::string(" (test ") + fdi::to_string(e.test) + ")";
  } else if (e.type == fdi::EventType::kReferenceRejected) {
    s += std::string(" (") + fdi::to_string(e.why) + ")";
  }
  return s;
}

}  // namespace

std::string LedgerExplainer::text(int n_gyros) const {
  std::string out = printf_text("the ledger at t = %.6g s\n", at_s_);
  if (health_) {
    const fdi::Health& h = *health_;
    const std::string parity = gyro_count(h.used) >= 4
                                   ? printf_text("chi2 %.4g (threshold %.4g), cusum %.4g (threshold %.4g)",
                                                 h.chi2, h.chi2_threshold, h.cusum, h.cusum_threshold)
                                   : std::string("no parity (fewer than four gyros in use)");
    out += printf_text("  at %.6g s: mode %s, gyros used %s, %s, reference %s\n", health_time_s_,
                       fdi::to_string(h.mode), mask_to_string(h.used, n_gyros).c_str(), parity.c_str(),
                       fdi::to_string(h.reference_state));
  } else {
    out += "  no epoch at or before that time\n";
  }
  if (decisions_.empty()) {
    out += "  no decision up to then\n";
    return out;
  }
  out += printf_text("  the last %zu decisions up to then, each with the rows that decided it:\n",
                     decisions_.size());
  for (const auto& d : decisions_) {
    out += printf_text("  %.6g s  %s\n", d.time_s, headline(d.event).c_str());
    for (const auto& row : d.event.ledger) out += "      " + fdi::to_text(row) + "\n";
  }
  return out;
}

}  // namespace tetra::report
