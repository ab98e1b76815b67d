// The fusion pipeline. Design and formulas: docs/fdi.md.
//
// Per epoch: input checks → calibrated rates y_i = (g_i − β_i)/s_i → one-epoch jump test (outliers) →
// weighted least squares rate over the usable gyros (cached pseudoinverse per subset) → normalized parity
// p = W y → χ² and CUSUM detection → isolation evidence (per-gyro signatures, onset, reference, GLT) →
// reconfiguration → attitude propagation and its uncertainty.
//
// Steady state allocates nothing: every buffer is sized at creation (or when the sample period is first
// known), the subset cache is filled in advance for N ≤ 8, and events reuse a reserved vector.

#include "tetra/fdi/pipeline.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <unordered_map>

#include "tetra/core/attitude.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/units.hpp"
#include "tetra/fdi/detectors.hpp"

namespace tetra::fdi {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kHistory = 256;        //!< [epochs] history kept for the onset test
constexpr int kSnapshots = 512;      //!< reference snapshots kept
constexpr int kSpikeMemory = 64;     //!< spike times kept per gyro
constexpr int kNoiseEvalEvery = 10;  //!< [samples] the noise-level test runs every this many samples
constexpr double kNoiseExpectedMedian = 0.6744897501960817;  //!< median of |N(0,1)|

//! Everything that depends on the gyro subset only; computed once per subset.
struct Subset {
  GyroMask mask = 0;
  bool observable = false;
  int dof = 0;                    //!< parity dimension |S| − 3
  Eigen::Matrix3Xd pinv;          //!< 3×N weighted pseudoinverse (zero columns outside S)
  Eigen::MatrixXd parity;         //!< d×N normalized parity in 1/(rad/s) per √s: p = √T·W·y ~ N(0, I)
  Eigen::Vector3d arw_sq_rad2_s;  //!< [rad²/s] N² per body axis of the rate estimate
  Eigen::Vector3d bias_sigma_rad_s;  //!< [rad/s] 1σ rate bias per body axis left by the calibration
  double chi2_threshold = 0.0;       //!< instantaneous χ² threshold
  double jump_threshold = 0.0;       //!< one-epoch jump χ² threshold
  double cusum_k = 0.0;              //!< [σ] CUSUM reference
  double cusum_h = 0.0;              //!< [σ] CUSUM threshold
  double glt_accept = 0.0;           //!< χ²_{d−1} quantile accepting a single-gyro hypothesis
  double glt_reject = 0.0;           //!< χ²_{d−1} quantile rejecting one
};

struct GyroTrack {
  bool excluded = false;
  FaultKind kind = FaultKind::kNone;
  double sigma_rate_rts = 0.0;    //!< [rad/√s] white rate noise N
  double bias_rate_sigma = 0.0;   //!< [rad/s] 1σ of the calibrated bias
  double scale_rel_sigma = 0.0;   //!< [-] 1σ relative scale factor error
  double bias_instability = 0.0;  //!< [rad/s] B of the calibration's noise section (0 if absent)
  // this epoch
  bool valid = false;  //!< sample present and valid (before the jump test)
  bool use = false;    //!< used in this epoch's solution
  double y = 0.0;      //!< [rad/s] calibrated rate
  double raw = 0.0;
  // last good sample (jump test reference)
  bool has_last_good = false;
  double last_good_y = 0.0;
  std::int64_t last_good_ns = 0;
  // timers
  std::int64_t absent_since_ns = -1;
  std::int64_t invalid_since_ns = -1;
  // repeated values
  bool has_last_raw = false;
  double last_raw = 0.0;
  int repeat_count = 0;
  // second differences for the noise-level test
  int consecutive = 0;
  double y1 = 0.0;
  double y2 = 0.0;
  std::vector<double> d2;  //!< ring of |Δ²y| [rad/s], size noise_window
  int d2_count = 0;
  int d2_head = 0;
  int d2_since_eval = 0;
  // outliers and spikes
  int outlier_run = 0;
  double outlier_first_raw = 0.0;
  bool outlier_repeated = true;
  std::array<std::int64_t, kSpikeMemory> spike_ns{};
  int spike_n = 0;  //!< total spikes recorded (ring index = n % memory)
  // reference comparison
  double angle_rad = 0.0;      //!< ∫ (y_i − h_i·ω_e) dt (trapezoid)
  double prev_int_y = 0.0;     //!< [rad/s] rate integrated at the previous epoch
  double ref_angle_rad = 0.0;  //!< Σ h_i·log(q_{k−1}* q_k) over the reference's own increments
};

struct Episode {
  bool active = false;  //!< a fault is detected and not isolated
  bool declared_unisolated = false;
  std::int64_t detect_ns = 0;
  std::int64_t deadline_ns = 0;
  std::int64_t last_alarm_ns = 0;
  std::int64_t onset_index = 0;  //!< estimated first faulty epoch (history index)
  std::int64_t onset_ns = 0;
  std::string test;
  double statistic = 0.0;
  // GLT accumulation (d ≥ 2)
  Eigen::VectorXd glt_sum;
  int glt_n = 0;
};

double deg2rad(double v) {
  return v * kDegToRad;
}

}  // namespace

class Pipeline::Impl {
 public:
  Impl(const Calibration& cal, const PipelineConfig& config)
      : cal_(cal),
        config_(config),
        n_(cal.gyro_count()),
        attitude_(config.initial_q_RB,
                  config.latitude_deg ? std::optional<double>(deg2rad(*config.latitude_deg)) : std::nullopt) {
  }

  Status init();
  void reset();
  const StepResult& step(const Epoch& epoch);
  FdiEvent command_exclude(int id, std::int64_t stamp_ns, bool force);
  FdiEvent command_reinstate(int id, std::int64_t stamp_ns);
  FdiEvent command_reset(std::int64_t stamp_ns);
  std::string describe_thresholds() const;

  const Health& health() const { return health_; }
  int gyro_count() const { return n_; }
  const PipelineConfig& config() const { return config_; }

 private:
  const Subset& subset(GyroMask mask);
  void build_subset(Subset& s, GyroMask mask) const;
  void prepare(double period_s);
  GyroMask active_mask() const;
  void emit(FdiEvent event);
  //! A "detected" event: `test` raised the alarm with `statistic`.
  void emit_detected(const std::string& test, double statistic, std::int64_t now);
  void reset_detectors();
  void check_signatures(std::int64_t now);
  void jump_test(std::int64_t now, GyroMask avail);
  int onset_test(std::int64_t now_index);
  int glt_test(const Subset& s) const;
  FaultKind classify_drift(int id);
  void reference_update(const Epoch& epoch);
  void isolate(int id, FaultKind kind, const std::string& evidence, const std::string& test, double statistic,
               std::int64_t now);
  Eigen::Vector3d fault_rate_bound(const Subset& s) const;
  void push_history(std::int64_t now);
  //! Robust noise level / expected over the last `last` second differences (0: the whole window).
  double noise_ratio(const GyroTrack& g, int last = 0) const;
  //! Trimmed RMS noise level / expected over the last `last` second differences (classification).
  double recent_noise_ratio(const GyroTrack& g, int last) const;
  void update_mode(std::int64_t now);
  //! Clears a gyro's exclusion and the fault evidence it carried (reinstate, reset).
  static void reinstate_track(GyroTrack& g);
  //! Queues and returns the acknowledgement "COMMAND ID: OUTCOME" of an operator command; when the
  //! command `changed` the gyro set, first resets the detectors and the mode, then also queues the
  //! reconfigured (or lost) event that follows it.
  FdiEvent acknowledge(const std::string& command, int id, const std::string& outcome, bool changed,
                       std::int64_t stamp_ns);

  Calibration cal_;
  PipelineConfig config_;
  int n_ = 0;
  Eigen::MatrixX3d axes_B_;
  std::vector<double> scale_V_per_rad_s_;
  std::vector<double> bias_V_;
  double period_s_ = 0.0;  //!< [s] nominal sample period T (0 until known)
  double sqrt_period_ = 0.0;
  std::unordered_map<GyroMask, Subset> subsets_;
  std::vector<GyroTrack> gyros_;
  AttitudePropagator attitude_;
  StepResult result_;
  std::vector<FdiEvent> pending_;  //!< command acknowledgements for the next step
  Health health_;
  Mode persistent_mode_ = Mode::kNominal;

  // time
  bool has_time_ = false;
  std::int64_t last_ns_ = 0;
  std::int64_t epoch_index_ = -1;  //!< index of the last accepted epoch

  // detection state (parity of the full active subset)
  GyroMask cusum_mask_ = 0;
  double cusum_pos_ = 0.0;
  double cusum_neg_ = 0.0;
  std::int64_t cusum_pos_start_ = 0;  //!< history index where the branch last left zero
  std::int64_t cusum_neg_start_ = 0;
  Eigen::VectorXd mcusum_;  //!< d ≥ 2: Crosier's vector CUSUM
  Eigen::VectorXd mc_sum_;  //!< Σ p since the vector CUSUM was last zero
  int mc_n_ = 0;
  std::int64_t mc_start_ = 0;
  Eigen::VectorXd p_ema_;  //!< EMA of the normalized parity (fault size estimate)
  Eigen::VectorXd p_;      //!< this epoch's parity
  Eigen::VectorXd dp_;     //!< scratch
  Episode episode_;
  Eigen::Vector3d omega_prev_ = Eigen::Vector3d::Zero();  //!< [rad/s] previous epoch's estimate
  Eigen::Vector3d omega_meas_ =
      Eigen::Vector3d::Zero();  //!< [rad/s] last rate estimate (Earth rate included)
  std::int64_t lost_since_ns_ = -1;

  // history for the onset test
  std::vector<double> hist_y_;  //!< kHistory×N
  std::vector<GyroMask> hist_valid_;
  std::vector<std::int64_t> hist_ns_;
  std::vector<double> hist_raw_;  //!< kHistory×N

  // reference snapshots
  std::vector<std::int64_t> snap_ns_;
  std::vector<Quaternion> snap_q_;
  std::vector<double> snap_angle_;       //!< kSnapshots×N
  std::vector<double> snap_ref_;         //!< kSnapshots×N
  int snap_count_ = 0;                   //!< total pushed
  int ref_run_gyro_ = 0;                 //!< gyro flagged alone by the last reference comparisons
  int ref_run_ = 0;                      //!< how many in a row
  mutable std::vector<double> scratch_;  //!< median scratch
  std::vector<double> mean_pre_, mean_post_;
  std::vector<int> n_pre_, n_post_;
};

// ---------------------------------------------------------------------------------------------
// set-up

Status Pipeline::Impl::init() {
  axes_B_ = cal_.axes_B();
  Eigen::VectorXd arw(n_);
  gyros_.resize(static_cast<std::size_t>(n_));
  for (int i = 0; i < n_; ++i) {
    const auto& g = cal_.gyros[static_cast<std::size_t>(i)];
    auto& t = gyros_[static_cast<std::size_t>(i)];
    const double n_dps =
        (g.noise && g.noise->arw_dps_rtHz) ? *g.noise->arw_dps_rtHz : config_.default_arw_dps_rtHz;
    if (!(n_dps > 0.0) || !std::isfinite(n_dps)) {
      return bad_input("calibration: gyro " + std::to_string(i + 1) +
                       ": noise.arw_dps_rtHz must be positive");
    }
    t.sigma_rate_rts = deg2rad(n_dps);
    if (g.noise && g.noise->bias_instability_dps)
      t.bias_instability = deg2rad(*g.noise->bias_instability_dps);
    arw[i] = t.sigma_rate_rts;
    const double s = config_.raw_units_dps ? 1.0 : g.scale_factor_V_per_dps;
    scale_V_per_rad_s_.push_back(s / kDegToRad);
    bias_V_.push_back(config_.raw_units_dps ? 0.0 : g.bias_V);
    if (g.sigma && !config_.raw_units_dps) {
      t.bias_rate_sigma = deg2rad(g.sigma->bias_V / std::abs(g.scale_factor_V_per_dps));
      t.scale_rel_sigma = g.sigma->scale_factor_V_per_dps / std::abs(g.scale_factor_V_per_dps);
    }
    t.d2.assign(static_cast<std::size_t>(config_.noise_window), 0.0);
  }
  auto geometry = GyroGeometry::create(axes_B_, arw);
  if (!geometry) return geometry.error();
  hist_y_.assign(static_cast<std::size_t>(kHistory) * static_cast<std::size_t>(n_), 0.0);
  hist_raw_.assign(static_cast<std::size_t>(kHistory) * static_cast<std::size_t>(n_), 0.0);
  hist_valid_.assign(kHistory, 0);
  hist_ns_.assign(kHistory, 0);
  snap_ns_.assign(kSnapshots, 0);
  snap_q_.assign(kSnapshots, Quaternion::Identity());
  snap_angle_.assign(static_cast<std::size_t>(kSnapshots) * static_cast<std::size_t>(n_), 0.0);
  snap_ref_.assign(static_cast<std::size_t>(kSnapshots) * static_cast<std::size_t>(n_), 0.0);
  scratch_.assign(static_cast<std::size_t>(std::max(config_.noise_window, 8)), 0.0);
  mean_pre_.assign(static_cast<std::size_t>(n_), 0.0);
  mean_post_.assign(static_cast<std::size_t>(n_), 0.0);
  n_pre_.assign(static_cast<std::size_t>(n_), 0);
  n_post_.assign(static_cast<std::size_t>(n_), 0);
  const Eigen::Index dmax = std::max(1, n_ - 3);
  mcusum_ = Eigen::VectorXd::Zero(dmax);
  mc_sum_ = Eigen::VectorXd::Zero(dmax);
  p_ema_ = Eigen::VectorXd::Zero(dmax);
  p_ = Eigen::VectorXd::Zero(dmax);
  dp_ = Eigen::VectorXd::Zero(dmax);
  episode_.glt_sum = Eigen::VectorXd::Zero(dmax);
  result_.events.reserve(32);
  pending_.reserve(16);
  health_.gyros.resize(static_cast<std::size_t>(n_));
  subsets_.reserve(n_ <= 8 ? 512 : 4096);
  if (config_.sample_period_s > 0.0) prepare(config_.sample_period_s);
  reset();
  return ok_status();
}

void Pipeline::Impl::prepare(double period_s) {
  period_s_ = period_s;
  sqrt_period_ = std::sqrt(period_s);
  // Every subset (unobservable ones too) is prepared in advance for small packages, so that a missing sample
  // never allocates; larger packages prepare the full set and its leave-one-out subsets.
  if (n_ <= 8) {
    for (GyroMask m = 0; m <= all_gyros(n_); ++m) (void)subset(m);
  } else {
    (void)subset(all_gyros(n_));
    for (int id = 1; id <= n_; ++id) (void)subset(without_gyro(all_gyros(n_), id));
  }
}

void Pipeline::Impl::build_subset(Subset& s, GyroMask mask) const {
  s.mask = mask;
  Eigen::VectorXd arw(n_);
  for (int i = 0; i < n_; ++i) arw[i] = gyros_[static_cast<std::size_t>(i)].sigma_rate_rts;
  const auto geometry = GyroGeometry::create(axes_B_, arw);
  s.observable = geometry && geometry->observable(mask);
  s.pinv = Eigen::Matrix3Xd::Zero(3, n_);
  s.arw_sq_rad2_s.setZero();
  s.bias_sigma_rad_s.setZero();
  if (!s.observable) return;
  s.pinv = *geometry->pseudoinverse(mask);
  s.arw_sq_rad2_s = *geometry->noise_variance_per_axis(mask);
  for (int a = 0; a < 3; ++a) {
    double v = 0.0;
    for (int i = 0; i < n_; ++i) {
      const double b = gyros_[static_cast<std::size_t>(i)].bias_rate_sigma;
      v += s.pinv(a, i) * s.pinv(a, i) * b * b;
    }
    s.bias_sigma_rad_s[a] = std::sqrt(v);
  }
  s.dof = tetra::gyro_count(mask) - 3;
  if (s.dof < 1) {
    s.parity = Eigen::MatrixXd::Zero(0, n_);
    return;
  }
  // Unit-weight parity V (V H = 0, V Vᵀ = I) whitened by the noise: cov(V y) = V R Vᵀ = L Lᵀ, W = L⁻¹ V.
  const Eigen::MatrixXd v = *geometry->parity_matrix(mask);
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(n_, n_);
  for (int i = 0; i < n_; ++i) r(i, i) = arw[i] * arw[i];
  const Eigen::MatrixXd cov = v * r * v.transpose();
  const Eigen::LLT<Eigen::MatrixXd> llt(cov);
  s.parity = llt.matrixL().solve(v);
  s.chi2_threshold = chi2_threshold(config_.chi2_false_alarm_probability, s.dof);
  s.jump_threshold = chi2_threshold(config_.jump_false_alarm_probability, s.dof);
  // Smallest parity shift [σ] a step of cusum_min_fault_dps on any gyro of the subset produces.
  double min_col = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n_; ++i) {
    if (has_gyro(mask, i + 1)) min_col = std::min(min_col, s.parity.col(i).norm());
  }
  const double delta = deg2rad(config_.cusum_min_fault_dps) * min_col * sqrt_period_;
  s.cusum_k = 0.5 * delta;
  s.cusum_h = cusum_threshold(s.cusum_k, config_.cusum_arl0_epochs);
  if (s.dof >= 2) {
    s.glt_accept = chi2_threshold(1e-3, s.dof - 1);
    s.glt_reject = chi2_threshold(config_.glt_false_alarm_probability, s.dof - 1);
  }
}

const Subset& Pipeline::Impl::subset(GyroMask mask) {
  auto it = subsets_.find(mask);
  if (it != subsets_.end()) return it->second;
  Subset& s = subsets_[mask];
  build_subset(s, mask);
  return s;
}

GyroMask Pipeline::Impl::active_mask() const {
  GyroMask m = 0;
  for (int i = 0; i < n_; ++i) {
    if (!gyros_[static_cast<std::size_t>(i)].excluded) m |= GyroMask{1} << static_cast<unsigned>(i);
  }
  return m;
}

void Pipeline::Impl::reset() {
  for (auto& g : gyros_) {
    const double n = g.sigma_rate_rts;
    const double b = g.bias_rate_sigma;
    const double s = g.scale_rel_sigma;
    const double bi = g.bias_instability;
    auto d2 = std::move(g.d2);
    g = GyroTrack{};
    g.bias_instability = bi;
    g.sigma_rate_rts = n;
    g.bias_rate_sigma = b;
    g.scale_rel_sigma = s;
    g.d2 = std::move(d2);
  }
  attitude_.reset(config_.initial_q_RB);
  has_time_ = false;
  last_ns_ = 0;
  epoch_index_ = -1;
  health_.counters = Counters{};
  persistent_mode_ = Mode::kNominal;
  omega_meas_.setZero();
  omega_prev_.setZero();
  lost_since_ns_ = -1;
  snap_count_ = 0;
  ref_run_gyro_ = 0;
  ref_run_ = 0;
  pending_.clear();
  reset_detectors();
  update_mode(0);
}

void Pipeline::Impl::reset_detectors() {
  cusum_mask_ = 0;
  cusum_pos_ = cusum_neg_ = 0.0;
  cusum_pos_start_ = cusum_neg_start_ = epoch_index_ + 1;
  mcusum_.setZero();
  mc_sum_.setZero();
  mc_n_ = 0;
  mc_start_ = epoch_index_ + 1;
  p_ema_.setZero();
  episode_.active = false;
  episode_.declared_unisolated = false;
  episode_.glt_sum.setZero();
  episode_.glt_n = 0;
  for (auto& g : gyros_) {
    g.outlier_run = 0;
    g.has_last_good = false;
  }
}

std::string Pipeline::Impl::describe_thresholds() const {
  std::string out = "gyros: " + std::to_string(n_) + "\n";
  for (int i = 0; i < n_; ++i) {
    out += "gyro " + std::to_string(i + 1) + ": N = ";
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", gyros_[static_cast<std::size_t>(i)].sigma_rate_rts * kRadToDeg);
    out += text;
    out += " deg/sqrt(s)\n";
  }
  const auto it = subsets_.find(all_gyros(n_));
  if (period_s_ > 0.0 && it != subsets_.end() && it->second.dof >= 1) {
    const Subset& s = it->second;
    out += "sample period: ";
    append_double(out, period_s_);
    out += " s\nparity dimension: " + std::to_string(s.dof) + "\nchi2 threshold: ";
    append_double(out, s.chi2_threshold);
    out += "\ncusum k (sigma): ";
    append_double(out, s.cusum_k);
    out += "\ncusum h (sigma): ";
    append_double(out, s.cusum_h);
    out += "\n";
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// events and modes

void Pipeline::Impl::emit(FdiEvent event) {
  result_.events.push_back(std::move(event));
}

void Pipeline::Impl::emit_detected(const std::string& test, double statistic, std::int64_t now) {
  FdiEvent d;
  d.stamp_ns = now;
  d.type = EventType::kDetected;
  d.test = test;
  d.statistic = statistic;
  emit(std::move(d));
}

void Pipeline::Impl::update_mode(std::int64_t now) {
  const GyroMask active = active_mask();
  Mode mode = Mode::kNominal;
  const bool observable = period_s_ > 0.0 ? subset(active).observable : tetra::gyro_count(active) >= 3;
  if (!observable) {
    mode = Mode::kLost;
  } else if (episode_.active) {
    mode = Mode::kSuspect;
  } else if (active != all_gyros(n_)) {
    mode = Mode::kDegraded;
  }
  persistent_mode_ = mode;
  health_.stamp_ns = now;
  health_.mode = mode;
  for (int i = 0; i < n_; ++i) {
    const auto& g = gyros_[static_cast<std::size_t>(i)];
    auto& h = health_.gyros[static_cast<std::size_t>(i)];
    h.kind = g.kind;
    if (g.excluded) {
      h.state = GyroState::kExcluded;
    } else if (g.outlier_run > 0) {
      h.state = GyroState::kSuspect;
    } else if (g.invalid_since_ns >= 0) {
      h.state = GyroState::kInvalid;
    } else if (g.absent_since_ns >= 0) {
      h.state = GyroState::kAbsent;
    } else {
      h.state = GyroState::kOk;
    }
  }
}

void Pipeline::Impl::isolate(int id, FaultKind kind, const std::string& evidence, const std::string& test,
                             double statistic, std::int64_t now) {
  auto& g = gyros_[static_cast<std::size_t>(id - 1)];
  if (g.excluded) return;
  const GyroMask before = active_mask();
  if (!episode_.active) {
    emit_detected(test, statistic, now);
  } else if (period_s_ > 0.0) {
    // The fault corrupted the rate from its onset until now: keep that in the attitude uncertainty.
    const Subset& s = subset(before);
    if (s.observable && s.dof >= 1) {
      const Eigen::VectorXd w = s.parity.col(id - 1) * sqrt_period_;
      // p_ema_ is sized for N − 3 parity rows; this subset has s.dof of them (fewer once a gyro is out).
      const double f = w.dot(p_ema_.head(s.dof)) / std::max(w.squaredNorm(), 1e-300);
      const double span = ns_to_seconds(now - episode_.onset_ns);
      attitude_.add_bound(s.pinv.col(id - 1) * f * span);
    }
  }
  FdiEvent iso;
  iso.stamp_ns = now;
  iso.type = EventType::kIsolated;
  iso.gyro = id;
  iso.kind = kind;
  iso.evidence = evidence;
  iso.test = test;
  iso.statistic = statistic;
  emit(std::move(iso));
  g.excluded = true;
  g.kind = kind;
  reset_detectors();
  const GyroMask after = active_mask();
  FdiEvent rc;
  rc.stamp_ns = now;
  rc.gyros = after;
  const bool observable = period_s_ > 0.0 ? subset(after).observable : tetra::gyro_count(after) >= 3;
  rc.type = observable ? EventType::kReconfigured : EventType::kLost;
  emit(std::move(rc));
  update_mode(now);
}

// ---------------------------------------------------------------------------------------------
// per-gyro signatures

double Pipeline::Impl::noise_ratio(const GyroTrack& g, int last) const {
  const int n = last > 0 ? std::min({last, g.d2_count, config_.noise_window})
                         : std::min(g.d2_count, config_.noise_window);
  if (n < (last > 0 ? std::min(10, config_.noise_window) : config_.noise_window)) return kNaN;
  double* buf = scratch_.data();
  if (n == config_.noise_window) {
    std::copy(g.d2.begin(), g.d2.end(), buf);  // the whole ring: order does not matter for a median
  } else {
    for (int k = 0; k < n; ++k) {
      buf[k] = g.d2[static_cast<std::size_t>((g.d2_head - 1 - k + 2 * config_.noise_window) %
                                             config_.noise_window)];
    }
  }
  std::nth_element(buf, buf + n / 2, buf + n);
  // Δ²y = y_k − 2y_{k−1} + y_{k−2} of white noise has variance 6σ²: median |Δ²y| = 0.6745·√6·σ.
  const double sigma_sample = g.sigma_rate_rts / sqrt_period_;
  return buf[n / 2] / (kNoiseExpectedMedian * std::sqrt(6.0) * sigma_sample);
}

double Pipeline::Impl::recent_noise_ratio(const GyroTrack& g, int last) const {
  // RMS of the last `last` second differences without their two largest (a step leaves exactly two), over the
  // expected √6·σ. Efficient on few samples, where the median is not: used to classify at isolation time.
  const int n = std::min({last, g.d2_count, config_.noise_window});
  if (n < 6) return kNaN;
  double* buf = scratch_.data();
  for (int k = 0; k < n; ++k) {
    buf[k] =
        g.d2[static_cast<std::size_t>((g.d2_head - 1 - k + 2 * config_.noise_window) % config_.noise_window)];
  }
  std::sort(buf, buf + n);
  double sum_sq = 0.0;
  for (int k = 0; k < n - 2; ++k) sum_sq += buf[k] * buf[k];
  const double sigma_sample = g.sigma_rate_rts / sqrt_period_;
  return std::sqrt(sum_sq / (n - 2)) / (std::sqrt(6.0) * sigma_sample);
}

void Pipeline::Impl::check_signatures(std::int64_t now) {
  for (int i = 0; i < n_; ++i) {
    auto& g = gyros_[static_cast<std::size_t>(i)];
    if (g.excluded) continue;
    const int id = i + 1;
    if (g.absent_since_ns >= 0 && now - g.absent_since_ns >= seconds_to_ns(config_.dropout_timeout_s)) {
      isolate(id, FaultKind::kDropout, "timeout", "signature", ns_to_seconds(now - g.absent_since_ns), now);
      continue;
    }
    if (g.invalid_since_ns >= 0 && now - g.invalid_since_ns >= seconds_to_ns(config_.invalid_timeout_s)) {
      isolate(id, FaultKind::kInvalid, "invalid", "signature", ns_to_seconds(now - g.invalid_since_ns), now);
      continue;
    }
    if (g.repeat_count >= config_.stuck_repeat_count) {
      isolate(id, FaultKind::kStuck, g.last_raw == 0.0 ? "zero" : "repeated", "signature", g.repeat_count,
              now);
      continue;
    }
    if (g.d2_since_eval >= kNoiseEvalEvery && period_s_ > 0.0) {
      g.d2_since_eval = 0;
      const double r = noise_ratio(g);
      if (std::isfinite(r) && r > config_.noise_high_ratio) {
        isolate(id, FaultKind::kNoise, "noise-level", "signature", r, now);
        continue;
      }
      if (std::isfinite(r) && r < config_.noise_low_ratio) {
        isolate(id, FaultKind::kStuck, "variance", "signature", r, now);
        continue;
      }
    }
    // Recurring spikes: enough confirmed one-epoch outliers within the window, the first one old enough
    // for the noise-level test to have spoken, and the gyro's noise level otherwise normal.
    if (g.spike_n >= config_.spike_count) {
      const int first = (g.spike_n - config_.spike_count) % kSpikeMemory;
      const std::int64_t t_first = g.spike_ns[static_cast<std::size_t>(first)];
      const std::int64_t age = now - t_first;
      if (age <= seconds_to_ns(config_.spike_window_s) &&
          age >= seconds_to_ns(3.0 * kNoiseEvalEvery * period_s_ + config_.noise_window * period_s_)) {
        const double r = noise_ratio(g);
        if (std::isfinite(r) && r < 0.5 * config_.noise_high_ratio) {
          isolate(id, FaultKind::kSpike, "recurring-spikes", "signature", config_.spike_count, now);
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// one-epoch jump test: a significant jump of the parity that exactly one single-gyro hypothesis
// explains with a physically possible motion leaves that gyro's sample out for this epoch.

void Pipeline::Impl::jump_test(std::int64_t now, GyroMask avail) {
  const Subset& s = subset(avail);
  if (!s.observable || s.dof < 1) return;
  double dt_max = 0.0;
  for (int i = 0; i < n_; ++i) {
    if (!has_gyro(avail, i + 1)) continue;
    const auto& g = gyros_[static_cast<std::size_t>(i)];
    if (!g.has_last_good) return;
    dt_max = std::max(dt_max, ns_to_seconds(now - g.last_good_ns));
  }
  // Δp = √T·W·Δy/√2 (a difference of two samples has twice the variance).
  auto dy = [&](int i) {
    const auto& g = gyros_[static_cast<std::size_t>(i)];
    return g.y - g.last_good_y;
  };
  double chi2 = 0.0;
  for (int r = 0; r < s.dof; ++r) {
    double acc = 0.0;
    for (int i = 0; i < n_; ++i) {
      if (has_gyro(avail, i + 1)) acc += s.parity(r, i) * dy(i);
    }
    acc *= sqrt_period_ / std::sqrt(2.0);
    chi2 += acc * acc;
  }
  if (chi2 <= s.jump_threshold) return;
  const double a_max = deg2rad(config_.max_angular_acceleration_dps2);
  int consistent = 0;
  int culprit = 0;
  for (int j = 0; j < n_; ++j) {
    if (!has_gyro(avail, j + 1)) continue;
    const Subset& h = subset(without_gyro(avail, j + 1));
    if (!h.observable) return;  // cannot judge: no outlier call
    Eigen::Vector3d dw = Eigen::Vector3d::Zero();
    double var = 0.0;
    for (int i = 0; i < n_; ++i) {
      if (!has_gyro(h.mask, i + 1)) continue;
      dw += h.pinv.col(i) * dy(i);
      const double sig = gyros_[static_cast<std::size_t>(i)].sigma_rate_rts / sqrt_period_;
      var += h.pinv.col(i).squaredNorm() * 2.0 * sig * sig;
    }
    bool ok = dw.norm() <= a_max * dt_max + config_.onset_sigma * std::sqrt(var);
    if (ok && h.dof >= 1) {
      double c2 = 0.0;
      for (int r = 0; r < h.dof; ++r) {
        double acc = 0.0;
        for (int i = 0; i < n_; ++i) {
          if (has_gyro(h.mask, i + 1)) acc += h.parity(r, i) * dy(i);
        }
        acc *= sqrt_period_ / std::sqrt(2.0);
        c2 += acc * acc;
      }
      ok = c2 <= h.jump_threshold;
    }
    if (ok) {
      ++consistent;
      culprit = j;
    }
  }
  if (consistent != 1) return;
  auto& g = gyros_[static_cast<std::size_t>(culprit)];
  g.use = false;
  ++health_.counters.samples_outlier;
  if (g.outlier_run == 0) {
    g.outlier_first_raw = g.raw;
    g.outlier_repeated = true;
  } else {
    g.outlier_repeated = g.outlier_repeated && g.raw == g.outlier_first_raw;
  }
  ++g.outlier_run;
}

// ---------------------------------------------------------------------------------------------
// onset test over windows before and after the CUSUM's change-time estimate

int Pipeline::Impl::onset_test(std::int64_t now_index) {
  const std::int64_t k0 = episode_.onset_index;
  const std::int64_t gap = 2;
  const std::int64_t pre_begin = k0 - gap - config_.onset_pre_epochs;
  const std::int64_t pre_end = k0 - gap;
  const std::int64_t post_end = std::min(now_index + 1, k0 + config_.onset_post_max_epochs);
  if (pre_begin < 0 || pre_begin <= now_index - kHistory || post_end - k0 < 20) return 0;
  std::fill(mean_pre_.begin(), mean_pre_.end(), 0.0);
  std::fill(mean_post_.begin(), mean_post_.end(), 0.0);
  std::fill(n_pre_.begin(), n_pre_.end(), 0);
  std::fill(n_post_.begin(), n_post_.end(), 0);
  double t_pre = 0.0;
  double t_post = 0.0;
  auto accumulate = [&](std::int64_t b, std::int64_t e, std::vector<double>& mean, std::vector<int>& cnt,
                        double& t_mean) {
    for (std::int64_t k = b; k < e; ++k) {
      const auto slot = static_cast<std::size_t>(k % kHistory);
      t_mean += ns_to_seconds(hist_ns_[slot] - hist_ns_[static_cast<std::size_t>(b % kHistory)]);
      for (int i = 0; i < n_; ++i) {
        if (!has_gyro(hist_valid_[slot], i + 1)) continue;
        mean[static_cast<std::size_t>(i)] +=
            hist_y_[slot * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i)];
        ++cnt[static_cast<std::size_t>(i)];
      }
    }
    t_mean /= static_cast<double>(e - b);
    for (int i = 0; i < n_; ++i) {
      if (cnt[static_cast<std::size_t>(i)] > 0)
        mean[static_cast<std::size_t>(i)] /= cnt[static_cast<std::size_t>(i)];
    }
  };
  accumulate(pre_begin, pre_end, mean_pre_, n_pre_, t_pre);
  accumulate(k0, post_end, mean_post_, n_post_, t_post);
  const double separation = ns_to_seconds(hist_ns_[static_cast<std::size_t>(k0 % kHistory)] -
                                          hist_ns_[static_cast<std::size_t>(pre_begin % kHistory)]) +
                            t_post - t_pre;
  const double a_max = deg2rad(config_.max_angular_acceleration_dps2);
  const GyroMask active = active_mask();
  auto consistent = [&](GyroMask mask) -> int {  // 1 consistent, 0 not, −1 cannot judge
    const Subset& h = subset(mask);
    if (!h.observable) return -1;
    Eigen::Vector3d dw = Eigen::Vector3d::Zero();
    double var = 0.0;
    for (int i = 0; i < n_; ++i) {
      if (!has_gyro(mask, i + 1)) continue;
      const auto u = static_cast<std::size_t>(i);
      if (n_pre_[u] < 2 || n_post_[u] < 2) return -1;
      dw += h.pinv.col(i) * (mean_post_[u] - mean_pre_[u]);
      const double sig = gyros_[u].sigma_rate_rts / sqrt_period_;
      var += h.pinv.col(i).squaredNorm() * sig * sig * (1.0 / n_pre_[u] + 1.0 / n_post_[u]);
    }
    return dw.norm() <= a_max * separation + config_.onset_sigma * std::sqrt(var) ? 1 : 0;
  };
  if (consistent(active) != 0) return 0;  // no abrupt change beyond motion: nothing to tell
  int count = 0;
  int culprit = 0;
  for (int j = 1; j <= n_; ++j) {
    if (!has_gyro(active, j)) continue;
    const int c = consistent(without_gyro(active, j));
    if (c < 0) return 0;
    if (c == 1) {
      ++count;
      culprit = j;
    }
  }
  return count == 1 ? culprit : 0;
}

// GLT on the mean normalized parity since the onset (N ≥ 5): the residual after fitting a fault of
// gyro i is χ²_{d−1} under hypothesis i. Isolate i when it is accepted and every other is rejected.
int Pipeline::Impl::glt_test(const Subset& s) const {
  if (s.dof < 2 || episode_.glt_n < 3) return 0;
  const double n = episode_.glt_n;
  const Eigen::VectorXd mean = episode_.glt_sum.head(s.dof) / n;
  int best = 0;
  int accepted = 0;
  int rejected = 0;
  int members = 0;
  for (int i = 0; i < n_; ++i) {
    if (!has_gyro(s.mask, i + 1)) continue;
    ++members;
    const Eigen::VectorXd w = s.parity.col(i);
    const double proj = w.dot(mean);
    const double r = n * (mean.squaredNorm() - proj * proj / w.squaredNorm());
    if (r <= s.glt_accept) {
      ++accepted;
      best = i + 1;
    } else if (r > s.glt_reject) {
      ++rejected;
    }
  }
  return (accepted == 1 && rejected == members - 1) ? best : 0;
}

// Bias or ramp: fit p_j(τ) = c + b·τ to the parity projected on gyro j's direction over the history
// since the onset (at most kHistory epochs): a step leaves b ≈ 0, a ramp a significant slope.
// Without parity (three gyros) the data cannot tell: unknown.
FaultKind Pipeline::Impl::classify_drift(int id) {
  const GyroMask active = active_mask();
  const Subset& s = subset(active);
  if (!s.observable || s.dof < 1) return FaultKind::kUnknown;
  const Eigen::VectorXd w = s.parity.col(id - 1) / s.parity.col(id - 1).norm();
  const std::int64_t first = std::max<std::int64_t>(
      {episode_.active ? episode_.onset_index : epoch_index_ - kHistory + 1, epoch_index_ - kHistory + 1, 0});
  double n = 0.0;
  double st = 0.0;
  double sp = 0.0;
  double stt = 0.0;
  double stp = 0.0;
  const std::int64_t t0 = hist_ns_[static_cast<std::size_t>(first % kHistory)];
  for (std::int64_t k = first; k <= epoch_index_; ++k) {
    const auto slot = static_cast<std::size_t>(k % kHistory);
    if ((hist_valid_[slot] & active) != active) continue;
    double proj = 0.0;
    for (int r = 0; r < s.dof; ++r) {
      double acc = 0.0;
      for (int i = 0; i < n_; ++i) {
        if (has_gyro(active, i + 1))
          acc += s.parity(r, i) * hist_y_[slot * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i)];
      }
      proj += w[r] * acc * sqrt_period_;
    }
    const double t = ns_to_seconds(hist_ns_[slot] - t0);
    n += 1.0;
    st += t;
    sp += proj;
    stt += t * t;
    stp += t * proj;
  }
  if (n < 20.0) return FaultKind::kUnknown;
  const double sxx = stt - st * st / n;
  if (sxx <= 0.0) return FaultKind::kUnknown;
  const double slope = (stp - st * sp / n) / sxx;   // [σ/s]
  const double slope_sigma = 1.0 / std::sqrt(sxx);  // unit noise of the normalized parity
  return std::abs(slope) > 5.0 * slope_sigma ? FaultKind::kRamp : FaultKind::kBias;
}

// ---------------------------------------------------------------------------------------------
// reference: per-gyro integrated angle against the rotation the reference saw about that axis

void Pipeline::Impl::reference_update(const Epoch& epoch) {
  const std::int64_t now = epoch.stamp_ns;
  const Quaternion q = canonical(*epoch.reference_q_RB);
  // The reference's rotation about each gyro axis, summed over its own increments: one increment spans one
  // reference period, so the non-commutativity of a long window (slews) does not enter.
  if (snap_count_ > 0) {
    const auto prev = static_cast<std::size_t>((snap_count_ - 1) % kSnapshots);
    const Eigen::Vector3d inc_B = quat_log(snap_q_[prev].conjugate() * q);
    for (int i = 0; i < n_; ++i)
      gyros_[static_cast<std::size_t>(i)].ref_angle_rad += axes_B_.row(i).dot(inc_B);
  }
  const int slot = snap_count_ % kSnapshots;
  snap_ns_[static_cast<std::size_t>(slot)] = now;
  snap_q_[static_cast<std::size_t>(slot)] = q;
  for (int i = 0; i < n_; ++i) {
    snap_angle_[static_cast<std::size_t>(slot) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i)] =
        gyros_[static_cast<std::size_t>(i)].angle_rad;
    snap_ref_[static_cast<std::size_t>(slot) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i)] =
        gyros_[static_cast<std::size_t>(i)].ref_angle_rad;
  }
  ++snap_count_;
  // Oldest snapshot inside the window, at least half a window old.
  const std::int64_t window = seconds_to_ns(config_.reference_window_s);
  int old = -1;
  for (int k = std::max(0, snap_count_ - kSnapshots); k < snap_count_ - 1; ++k) {
    const std::int64_t t = snap_ns_[static_cast<std::size_t>(k % kSnapshots)];
    if (now - t <= window) {
      old = k;
      break;
    }
  }
  if (old < 0) return;
  const auto os = static_cast<std::size_t>(old % kSnapshots);
  const std::int64_t span_ns = now - snap_ns_[os];
  if (span_ns < window / 2) return;
  const double span = ns_to_seconds(span_ns);
  const double sig_ref = config_.reference_sigma_arcsec * kArcsecToRad;
  int flagged = 0;
  int loud = 0;
  int culprit = 0;
  double stat = 0.0;
  int members = 0;
  for (int i = 0; i < n_; ++i) {
    const auto& g = gyros_[static_cast<std::size_t>(i)];
    if (g.excluded) continue;
    ++members;
    const double rot =
        g.ref_angle_rad - snap_ref_[os * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i)];
    const double gyro_angle =
        g.angle_rad - snap_angle_[os * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i)];
    const double err = gyro_angle - rot;
    const double sig = std::sqrt(2.0 * sig_ref * sig_ref + g.sigma_rate_rts * g.sigma_rate_rts * span +
                                 std::pow((g.bias_rate_sigma + g.bias_instability) * span, 2) +
                                 std::pow(g.scale_rel_sigma * rot, 2));
    const double z = std::abs(err) / sig;
    if (z > config_.reference_threshold_sigma) {
      ++flagged;
      culprit = i + 1;
      stat = z;
    } else if (z > 0.5 * config_.reference_threshold_sigma) {
      ++loud;
    }
  }
  // One gyro alone beyond the threshold, the others quiet, in `reference_confirm_count` consecutive
  // comparisons (consecutive windows share no reference sample, so one wild reference sample cannot do it).
  if (flagged != 1 || loud != 0 || members < 2) {
    ref_run_gyro_ = 0;
    ref_run_ = 0;
    return;
  }
  if (culprit != ref_run_gyro_) {
    ref_run_gyro_ = culprit;
    ref_run_ = 0;
  }
  if (++ref_run_ < config_.reference_confirm_count) return;
  ref_run_gyro_ = 0;
  ref_run_ = 0;
  // Scale or rate offset: fit err(τ) = a·τ + b·rot(τ) over the window's snapshots. When the rotation about
  // the axis is not proportional to time (a slew), a significant b is a scale error; otherwise the data
  // cannot tell scale from offset and the parity's history decides bias or ramp.
  double stt = 0.0, str = 0.0, srr = 0.0, ste = 0.0, sre = 0.0;
  const auto c = static_cast<std::size_t>(culprit - 1);
  const std::size_t nn = static_cast<std::size_t>(n_);
  for (int k = old + 1; k < snap_count_; ++k) {
    const auto ks = static_cast<std::size_t>(k % kSnapshots);
    const double tau = ns_to_seconds(snap_ns_[ks] - snap_ns_[os]);
    const double rot = snap_ref_[ks * nn + c] - snap_ref_[os * nn + c];
    const double err = (snap_angle_[ks * nn + c] - snap_angle_[os * nn + c]) - rot;
    stt += tau * tau;
    str += tau * rot;
    srr += rot * rot;
    ste += tau * err;
    sre += rot * err;
  }
  FaultKind kind = classify_drift(culprit);
  const double det = stt * srr - str * str;
  if (stt > 0.0 && srr > 0.0 && det > 1e-4 * stt * srr) {  // |corr(τ, rot)| < 0.99995
    const double b = (stt * sre - str * ste) / det;
    const double sigma_b = std::sqrt(2.0) * sig_ref * std::sqrt(stt / det);
    if (std::abs(b) > 5.0 * sigma_b) kind = FaultKind::kScale;
  }
  isolate(culprit, kind, "reference", "reference", stat, now);
}

// ---------------------------------------------------------------------------------------------

Eigen::Vector3d Pipeline::Impl::fault_rate_bound(const Subset& s) const {
  // Rate error under each single-gyro hypothesis: gyro i carries the fault f_i = wᵢᵀp̄/|wᵢ|² [rad/s],
  // which moves the estimate by H*_{:,i} f_i. The bound covers all hypotheses, per axis.
  Eigen::Vector3d bound = Eigen::Vector3d::Zero();
  if (s.dof < 1) return bound;
  for (int i = 0; i < n_; ++i) {
    if (!has_gyro(s.mask, i + 1)) continue;
    double wp = 0.0;
    double ww = 0.0;
    for (int r = 0; r < s.dof; ++r) {
      const double w = s.parity(r, i) * sqrt_period_;
      wp += w * p_ema_[r];
      ww += w * w;
    }
    const double f = wp / ww;
    bound = bound.cwiseMax((s.pinv.col(i) * f).cwiseAbs());
  }
  return bound;
}

void Pipeline::Impl::push_history(std::int64_t now) {
  const auto slot = static_cast<std::size_t>(epoch_index_ % kHistory);
  hist_ns_[slot] = now;
  GyroMask valid = 0;
  for (int i = 0; i < n_; ++i) {
    const auto& g = gyros_[static_cast<std::size_t>(i)];
    hist_y_[slot * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i)] = g.y;
    hist_raw_[slot * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i)] = g.raw;
    if (g.valid) valid |= GyroMask{1} << static_cast<unsigned>(i);
  }
  hist_valid_[slot] = valid;
}

const StepResult& Pipeline::Impl::step(const Epoch& epoch) {
  result_.events.clear();
  for (auto& e : pending_) result_.events.push_back(std::move(e));
  pending_.clear();
  result_.accepted = false;
  const std::int64_t now = epoch.stamp_ns;
  auto& counters = health_.counters;
  if (static_cast<int>(epoch.raw.size()) != n_ || static_cast<int>(epoch.present.size()) != n_) {
    ++counters.epochs_rejected_shape;
    return result_;
  }
  if (has_time_ && now <= last_ns_) {
    ++counters.epochs_rejected_time;
    return result_;
  }
  const double dt = has_time_ ? ns_to_seconds(now - last_ns_) : 0.0;
  if (period_s_ <= 0.0 && dt > 0.0) prepare(dt);
  has_time_ = true;
  last_ns_ = now;
  ++epoch_index_;
  ++counters.epochs_accepted;
  result_.accepted = true;

  // 1. input checks and calibration
  const double max_rate = deg2rad(config_.max_abs_rate_dps);
  for (int i = 0; i < n_; ++i) {
    auto& g = gyros_[static_cast<std::size_t>(i)];
    const auto u = static_cast<std::size_t>(i);
    g.valid = false;
    g.use = false;
    if (epoch.present[u] == 0) {
      ++counters.samples_absent;
      if (g.absent_since_ns < 0) g.absent_since_ns = now;
      g.consecutive = 0;
      continue;
    }
    g.absent_since_ns = -1;
    const double raw = epoch.raw[u];
    double y = kNaN;
    if (std::isfinite(raw) && std::abs(raw) <= config_.max_abs_raw_V)
      y = (raw - bias_V_[u]) / scale_V_per_rad_s_[u];
    if (!std::isfinite(y) || std::abs(y) > max_rate) {
      ++counters.samples_invalid;
      if (g.invalid_since_ns < 0) g.invalid_since_ns = now;
      g.consecutive = 0;
      continue;
    }
    g.invalid_since_ns = -1;
    ++counters.samples_accepted;
    g.valid = true;
    g.use = !g.excluded;
    g.raw = raw;
    g.y = y;
    // repeated raw values
    if (g.has_last_raw && raw == g.last_raw) {
      ++g.repeat_count;
    } else {
      g.repeat_count = 1;
    }
    g.has_last_raw = true;
    g.last_raw = raw;
    // second differences
    if (g.consecutive >= 2) {
      g.d2[static_cast<std::size_t>(g.d2_head)] = std::abs(y - 2.0 * g.y1 + g.y2);
      g.d2_head = (g.d2_head + 1) % config_.noise_window;
      ++g.d2_count;
      ++g.d2_since_eval;
    }
    g.y2 = g.y1;
    g.y1 = y;
    g.consecutive = std::min(g.consecutive + 1, 2);
  }
  if (epoch_index_ >= 0) push_history(now);

  GyroMask avail = 0;
  for (int i = 0; i < n_; ++i) {
    if (gyros_[static_cast<std::size_t>(i)].use) avail |= GyroMask{1} << static_cast<unsigned>(i);
  }

  if (period_s_ > 0.0) {
    // 2. one-epoch outliers
    jump_test(now, avail);
    for (int i = 0; i < n_; ++i) {
      auto& g = gyros_[static_cast<std::size_t>(i)];
      if (!has_gyro(avail, i + 1)) continue;
      if (!g.use) {  // outlier this epoch
        avail = without_gyro(avail, i + 1);
        if (g.outlier_run >= config_.onset_confirm_epochs) {
          const bool zero = g.outlier_repeated && g.raw == 0.0;
          const double r = recent_noise_ratio(g, config_.onset_confirm_epochs);
          if (g.outlier_repeated) {
            isolate(i + 1, FaultKind::kStuck, zero ? "zero" : "repeated", "onset", g.outlier_run, now);
          } else if (std::isfinite(r) && r > config_.noise_high_ratio) {
            isolate(i + 1, FaultKind::kNoise, "noise-level", "onset", r, now);
          } else {
            isolate(i + 1, FaultKind::kBias, "onset", "onset", g.outlier_run, now);
          }
        }
        continue;
      }
      if (g.outlier_run > 0) {  // the outlier went away: a spike
        g.outlier_run = 0;
        ++counters.spikes;
        g.spike_ns[static_cast<std::size_t>(g.spike_n % kSpikeMemory)] = now;
        ++g.spike_n;
      }
      g.has_last_good = true;
      g.last_good_y = g.y;
      g.last_good_ns = now;
    }
    avail &= active_mask();
  }

  // 3. rate estimate and parity
  bool observable = false;
  if (period_s_ > 0.0) {
    const Subset& s = subset(avail);
    observable = s.observable;
    if (observable) {
      Eigen::Vector3d w = Eigen::Vector3d::Zero();
      for (int i = 0; i < n_; ++i) {
        if (has_gyro(avail, i + 1)) w += s.pinv.col(i) * gyros_[static_cast<std::size_t>(i)].y;
      }
      omega_meas_ = w;
    }
    double chi2 = 0.0;
    for (int r = 0; r < s.dof; ++r) {
      double acc = 0.0;
      for (int i = 0; i < n_; ++i) {
        if (has_gyro(avail, i + 1)) acc += s.parity(r, i) * gyros_[static_cast<std::size_t>(i)].y;
      }
      p_[r] = acc * sqrt_period_;
      chi2 += p_[r] * p_[r];
    }
    health_.chi2 = chi2;
    health_.chi2_threshold = s.chi2_threshold;
    health_.parity_residual = s.dof >= 1 ? std::sqrt(chi2) : 0.0;

    // 4. detection: χ² on any subset with parity, CUSUM on the full active subset only
    const GyroMask act = active_mask();
    bool alarm = false;
    std::string test;
    double statistic = 0.0;
    std::int64_t onset = epoch_index_;
    if (s.dof >= 1 && chi2 > s.chi2_threshold) {
      alarm = true;
      test = "chi2";
      statistic = chi2;
    }
    if (avail == act && s.dof >= 1) {
      if (cusum_mask_ != act) {
        cusum_mask_ = act;
        cusum_pos_ = cusum_neg_ = 0.0;
        mcusum_.setZero();
        mc_sum_.setZero();
        mc_n_ = 0;
        p_ema_.setZero();
      }
      const double alpha = std::min(1.0, dt / 2.0);  // EMA time constant 2 s
      for (int r = 0; r < s.dof; ++r) p_ema_[r] += alpha * (p_[r] - p_ema_[r]);
      double stat = 0.0;
      if (s.dof == 1) {
        if (cusum_pos_ <= 0.0) cusum_pos_start_ = epoch_index_;
        if (cusum_neg_ <= 0.0) cusum_neg_start_ = epoch_index_;
        cusum_pos_ = std::max(0.0, cusum_pos_ + p_[0] - s.cusum_k);
        cusum_neg_ = std::max(0.0, cusum_neg_ - p_[0] - s.cusum_k);
        stat = std::max(cusum_pos_, cusum_neg_);
        if (stat > s.cusum_h && !alarm) {
          alarm = true;
          test = "cusum";
          statistic = stat;
          onset = cusum_pos_ >= cusum_neg_ ? cusum_pos_start_ : cusum_neg_start_;
        }
      } else {
        // Crosier's multivariate CUSUM: C = |S + p|; S ← 0 if C ≤ k, else (S + p)(1 − k/C).
        const auto d = static_cast<Eigen::Index>(s.dof);
        if (mcusum_.head(d).squaredNorm() == 0.0) {
          mc_start_ = epoch_index_;
          mc_sum_.setZero();
          mc_n_ = 0;
        }
        dp_.head(d) = mcusum_.head(d) + p_.head(d);
        const double c = dp_.head(d).norm();
        if (c <= s.cusum_k) {
          mcusum_.setZero();
        } else {
          mcusum_.head(d) = dp_.head(d) * (1.0 - s.cusum_k / c);
        }
        mc_sum_.head(d) += p_.head(d);
        ++mc_n_;
        stat = mcusum_.head(d).norm();
        if (stat > s.cusum_h && !alarm) {
          alarm = true;
          test = "cusum";
          statistic = stat;
          onset = mc_start_;
        }
      }
      health_.cusum = stat;
      health_.cusum_threshold = s.cusum_h;
      if (episode_.active && s.dof >= 2) {
        episode_.glt_sum.head(s.dof) += p_.head(s.dof);
        ++episode_.glt_n;
      }
    }
    if (alarm) {
      if (!episode_.active) {
        episode_.active = true;
        episode_.declared_unisolated = false;
        episode_.detect_ns = now;
        episode_.deadline_ns = now + seconds_to_ns(config_.isolation_window_s);
        episode_.onset_index = onset;
        episode_.onset_ns = hist_ns_[static_cast<std::size_t>(std::max<std::int64_t>(onset, 0) % kHistory)];
        if (epoch_index_ - onset >= kHistory) episode_.onset_ns = now;
        episode_.test = test;
        episode_.statistic = statistic;
        if (s.dof >= 2) {
          episode_.glt_sum.head(s.dof) = mc_sum_.head(s.dof);
          episode_.glt_n = mc_n_;
        }
        emit_detected(test, statistic, now);
        // The fault acted since its onset: widen the uncertainty for the time already spent.
        attitude_.add_bound(fault_rate_bound(subset(act)) * ns_to_seconds(now - episode_.onset_ns));
      }
      episode_.last_alarm_ns = now;
      // Restart the CUSUM so a persisting fault keeps raising alarms (and a gone one stops).
      cusum_pos_ = cusum_neg_ = 0.0;
      mcusum_.setZero();
    }
  }

  // Reference comparison integrals up to this epoch: each gyro's own angle, Earth rate removed.
  // Samples are instantaneous rates at the sample time: the increment over (t_{k−1}, t_k] is the trapezoid.
  {
    const Eigen::Vector3d earth_B = attitude_.earth_rate_B();
    for (int i = 0; i < n_; ++i) {
      auto& g = gyros_[static_cast<std::size_t>(i)];
      if (g.excluded) continue;
      const double yi = has_gyro(avail, i + 1) ? g.y : axes_B_.row(i).dot(omega_meas_);
      if (dt > 0.0) g.angle_rad += (0.5 * (g.prev_int_y + yi) - axes_B_.row(i).dot(earth_B)) * dt;
      g.prev_int_y = yi;
    }
  }

  // 5. isolation
  check_signatures(now);
  if (epoch.reference_q_RB && period_s_ > 0.0) reference_update(epoch);
  if (episode_.active && period_s_ > 0.0) {
    int culprit = onset_test(epoch_index_);
    std::string evidence = "onset";
    if (culprit == 0) {
      culprit = glt_test(subset(active_mask()));
      evidence = "glt";
    }
    if (culprit > 0) {
      // Kind from the gyro's own samples: identical raw values (5 or more in a row, whatever the onset
      // estimate) are a stuck output; a noise increase also shifts window means, and its second differences
      // tell it apart.
      const auto& cg = gyros_[static_cast<std::size_t>(culprit - 1)];
      const bool repeated = cg.repeat_count >= 5;
      const double r = recent_noise_ratio(
          cg, static_cast<int>(std::max<std::int64_t>(epoch_index_ - episode_.onset_index, 20)));
      FaultKind kind = FaultKind::kBias;
      if (repeated) {
        kind = FaultKind::kStuck;
      } else if (std::isfinite(r) && r > config_.noise_high_ratio) {
        kind = FaultKind::kNoise;
      } else if (evidence == "glt") {
        kind = classify_drift(culprit);
      }
      // A noise level neither normal nor clearly high: wait for more samples rather than guess the kind.
      const bool ambiguous = !repeated && std::isfinite(r) && r > 0.5 * config_.noise_high_ratio &&
                             r <= config_.noise_high_ratio;
      if (!ambiguous) isolate(culprit, kind, evidence, episode_.test, episode_.statistic, now);
    } else if (!episode_.declared_unisolated && now >= episode_.deadline_ns) {
      episode_.declared_unisolated = true;
      FdiEvent u;
      u.stamp_ns = now;
      u.type = EventType::kUnisolated;
      u.test = episode_.test;
      u.statistic = episode_.statistic;
      u.detail = "no evidence tells which gyro; all gyros kept, sigma covers every single-gyro hypothesis";
      emit(std::move(u));
    } else if (now - episode_.last_alarm_ns > seconds_to_ns(config_.clear_after_s)) {
      episode_.active = false;
      FdiEvent c;
      c.stamp_ns = now;
      c.type = EventType::kCleared;
      c.gyros = active_mask();
      c.detail = "no alarm for clear_after_s";
      emit(std::move(c));
    }
  }
  update_mode(now);

  // 6. attitude
  avail &= active_mask();
  const Subset* sol = period_s_ > 0.0 ? &subset(avail) : nullptr;
  observable = sol != nullptr && sol->observable;
  if (sol == nullptr) {
    // First epoch: no time step yet, so no sample period and no subset cache; the rate is still
    // estimated (it is published, not integrated).
    Eigen::VectorXd arw(n_);
    for (int i = 0; i < n_; ++i) arw[i] = gyros_[static_cast<std::size_t>(i)].sigma_rate_rts;
    const auto geometry = GyroGeometry::create(axes_B_, arw);
    if (geometry && geometry->observable(avail)) {
      const Eigen::Matrix3Xd pinv = *geometry->pseudoinverse(avail);
      omega_meas_.setZero();
      for (int i = 0; i < n_; ++i) {
        if (has_gyro(avail, i + 1)) omega_meas_ += pinv.col(i) * gyros_[static_cast<std::size_t>(i)].y;
      }
      observable = true;
    }
  }
  Mode epoch_mode = persistent_mode_;
  if (!observable) epoch_mode = Mode::kLost;
  if (dt > 0.0 && sol != nullptr) {
    Eigen::Vector3d bound = Eigen::Vector3d::Zero();
    if (episode_.active) bound = fault_rate_bound(subset(active_mask()));
    if (!observable) {
      // Rate unobservable: keep the last estimate and bound what the motion may have changed since.
      if (lost_since_ns_ < 0) lost_since_ns_ = now;
      const double t_lost = ns_to_seconds(now - lost_since_ns_) + dt;
      bound += Eigen::Vector3d::Constant(deg2rad(config_.max_angular_acceleration_dps2) * t_lost);
    } else {
      lost_since_ns_ = -1;
    }
    const Eigen::Vector3d arw = observable ? sol->arw_sq_rad2_s : subset(active_mask()).arw_sq_rad2_s;
    const Eigen::Vector3d bias = observable ? sol->bias_sigma_rad_s : subset(active_mask()).bias_sigma_rad_s;
    (void)attitude_.step(0.5 * (omega_prev_ + omega_meas_), dt, arw, bias, bound);  // trapezoid
    result_.attitude.omega_B_rad_s = omega_meas_ - attitude_.earth_rate_B();
  } else {
    result_.attitude.omega_B_rad_s = omega_meas_ - attitude_.earth_rate_B();
  }
  result_.attitude.stamp_ns = now;
  result_.attitude.q_RB = attitude_.q_RB();
  result_.attitude.sigma_rad = attitude_.sigma_rad();
  result_.attitude.mode = epoch_mode;
  result_.attitude.gyros = observable ? avail : GyroMask{0};
  health_.used = result_.attitude.gyros;
  omega_prev_ = omega_meas_;
  return result_;
}

// ---------------------------------------------------------------------------------------------
// operator commands

void Pipeline::Impl::reinstate_track(GyroTrack& g) {
  g.excluded = false;
  g.kind = FaultKind::kNone;
  g.spike_n = 0;
  g.repeat_count = 0;
  g.d2_count = 0;
  g.d2_since_eval = 0;
}

FdiEvent Pipeline::Impl::acknowledge(const std::string& command, int id, const std::string& outcome,
                                     bool changed, std::int64_t stamp_ns) {
  if (changed) {
    reset_detectors();
    update_mode(stamp_ns);
  }
  FdiEvent ack;
  ack.stamp_ns = stamp_ns;
  ack.type = EventType::kCommand;
  ack.gyro = id;
  ack.detail = command + " " + std::to_string(id) + ": " + outcome;
  ack.refused = !changed;
  ack.gyros = active_mask();
  pending_.push_back(ack);
  if (changed) {
    FdiEvent rc;
    rc.stamp_ns = stamp_ns;
    rc.type = persistent_mode_ == Mode::kLost ? EventType::kLost : EventType::kReconfigured;
    rc.gyros = active_mask();
    pending_.push_back(rc);
  }
  return ack;
}

FdiEvent Pipeline::Impl::command_exclude(int id, std::int64_t stamp_ns, bool force) {
  if (id < 1 || id > n_) return acknowledge("exclude", id, "rejected, no such gyro", false, stamp_ns);
  auto& g = gyros_[static_cast<std::size_t>(id - 1)];
  if (g.excluded) return acknowledge("exclude", id, "already excluded", false, stamp_ns);
  const GyroMask after = without_gyro(active_mask(), id);
  const bool observable = period_s_ > 0.0 ? subset(after).observable : tetra::gyro_count(after) >= 3;
  if (!observable && !force) {
    return acknowledge("exclude", id, "refused, the rest could not determine attitude (force overrides)",
                       false, stamp_ns);
  }
  g.excluded = true;
  g.kind = FaultKind::kUnknown;
  return acknowledge("exclude", id, "done", true, stamp_ns);
}

FdiEvent Pipeline::Impl::command_reinstate(int id, std::int64_t stamp_ns) {
  if (id < 1 || id > n_) return acknowledge("reinstate", id, "rejected, no such gyro", false, stamp_ns);
  auto& g = gyros_[static_cast<std::size_t>(id - 1)];
  if (!g.excluded) return acknowledge("reinstate", id, "not excluded", false, stamp_ns);
  reinstate_track(g);
  snap_count_ = 0;  // the reinstated gyro's angle has a gap: restart the reference windows
  return acknowledge("reinstate", id, "done", true, stamp_ns);
}

FdiEvent Pipeline::Impl::command_reset(std::int64_t stamp_ns) {
  // FDI reset: every gyro reinstated, detectors and episode cleared; the attitude and time go on.
  for (auto& g : gyros_) reinstate_track(g);
  snap_count_ = 0;
  reset_detectors();
  update_mode(stamp_ns);
  FdiEvent ack;
  ack.stamp_ns = stamp_ns;
  ack.type = EventType::kCommand;
  ack.gyros = active_mask();
  ack.detail = "reset: done, all gyros reinstated";
  pending_.push_back(ack);
  FdiEvent c;
  c.stamp_ns = stamp_ns;
  c.type = EventType::kCleared;
  c.gyros = active_mask();
  pending_.push_back(c);
  return ack;
}

// ---------------------------------------------------------------------------------------------
// public API

Pipeline::Pipeline(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Pipeline::Pipeline(Pipeline&&) noexcept = default;
Pipeline& Pipeline::operator=(Pipeline&&) noexcept = default;
Pipeline::~Pipeline() = default;

Result<Pipeline> Pipeline::create(const Calibration& calibration, const PipelineConfig& config) {
  if (auto st = validate_calibration(calibration, "calibration"); !st) return st.error();
  if (auto st = validate(config); !st) return st.error();
  auto impl = std::make_unique<Impl>(calibration, config);
  if (auto st = impl->init(); !st) return st.error();
  return Pipeline(std::move(impl));
}

void Pipeline::reset() {
  impl_->reset();
}
const StepResult& Pipeline::step(const Epoch& epoch) {
  return impl_->step(epoch);
}
FdiEvent Pipeline::exclude(int gyro_id, std::int64_t stamp_ns, bool force) {
  return impl_->command_exclude(gyro_id, stamp_ns, force);
}
FdiEvent Pipeline::reinstate(int gyro_id, std::int64_t stamp_ns) {
  return impl_->command_reinstate(gyro_id, stamp_ns);
}
FdiEvent Pipeline::reset_command(std::int64_t stamp_ns) {
  return impl_->command_reset(stamp_ns);
}
const Health& Pipeline::health() const {
  return impl_->health();
}
int Pipeline::gyro_count() const {
  return impl_->gyro_count();
}
const PipelineConfig& Pipeline::config() const {
  return impl_->config();
}
std::string Pipeline::describe_thresholds() const {
  return impl_->describe_thresholds();
}

}  // namespace tetra::fdi
