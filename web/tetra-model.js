// The tetra plugin's model (web/tetra-plugin.js): the telemetry points of a unit, where each comes from
// in the stream's messages, and a unit's name in an Open MCT object key.
/* exported TetraModel */
// eslint-disable-next-line no-unused-vars
function TetraModel() {
  'use strict';
  const q = (i) => (m) => m.q[i];
  const vec = (field, i) => (m) => m[field][i];
  const euler = (axis) => (m) => m.euler_deg[axis];
  function attitudePoints() {
    return [
      ['q_w', 'Quaternion w', '', q(0)],
      ['q_x', 'Quaternion x', '', q(1)],
      ['q_y', 'Quaternion y', '', q(2)],
      ['q_z', 'Quaternion z', '', q(3)],
      ['roll_deg', 'Roll (Z-Y-X)', 'deg', euler('roll')],
      ['pitch_deg', 'Pitch (Z-Y-X)', 'deg', euler('pitch')],
      ['yaw_deg', 'Yaw (Z-Y-X)', 'deg', euler('yaw')],
      ['rate_x_dps', 'Rate X', 'deg/s', vec('rate_dps', 0)],
      ['rate_y_dps', 'Rate Y', 'deg/s', vec('rate_dps', 1)],
      ['rate_z_dps', 'Rate Z', 'deg/s', vec('rate_dps', 2)],
      ['sigma_x_deg', 'Sigma X', 'deg', vec('sigma_deg', 0)],
      ['sigma_y_deg', 'Sigma Y', 'deg', vec('sigma_deg', 1)],
      ['sigma_z_deg', 'Sigma Z', 'deg', vec('sigma_deg', 2)]
    ].map(([key, name, units, get]) => ({ key, name, units, source: 'attitude', get }));
  }
  function healthPoints(gyroCount) {
    const points = [
      { key: 'mode', name: 'Mode', source: 'health', get: (m) => m.mode, text: true },
      {
        key: 'parity_residual',
        name: 'Parity residual',
        units: 'sigma',
        source: 'health',
        get: (m) => m.parity_residual
      },
      {
        key: 'chi2',
        name: 'Chi-squared',
        source: 'health',
        get: (m) => m.chi2,
        limit: (m) => m.chi2_threshold
      },
      {
        key: 'cusum',
        name: 'CUSUM',
        source: 'health',
        get: (m) => m.cusum,
        limit: (m) => m.cusum_threshold
      },
      {
        key: 'health_age_s',
        name: 'Health age',
        units: 's',
        source: 'link',
        get: (m) => m.health_age_s,
        limit: (m) => m.stale_after_s
      },
      { key: 'link', name: 'Link state', source: 'link', get: (m) => m.state, text: true }
    ];
    for (let g = 1; g <= gyroCount; g++) {
      points.push({
        key: 'gyro' + g + '_state',
        name: 'Gyro ' + g + ' state',
        source: 'health',
        text: true,
        get: (m) => (m.gyros[g - 1] ? m.gyros[g - 1].state : undefined)
      });
    }
    return points;
  }
  function eventPoint() {
    return {
      key: 'events',
      name: 'FDI events',
      source: 'event',
      text: true,
      get: (m) => m.event + (m.gyro ? ' gyro ' + m.gyro : '') + (m.detail ? ': ' + m.detail : '')
    };
  }
  function pointsOf(unit) {
    return attitudePoints()
      .concat(healthPoints(unit.gyro_count || 4))
      .concat([eventPoint()]);
  }

  // A unit in an object key as 'x' and its unit_id (the ground's hexadecimal of the bytes of its name, the
  // DDS key as it came): any name (a space, a '~', a '%', a '/', bytes that are not UTF-8) survives Open
  // MCT's navigation path and the browser's URL encoding unchanged, and two names that look alike (both
  // shown with U+FFFD) keep keys of their own.
  function unitKey(unitId) {
    return 'x' + unitId;
  }
  // The unit_id of an object key; a key that is not 'x' and hexadecimal is taken as the name itself.
  function unitIdOfKey(text) {
    if (/^x([0-9a-f]{2})*$/.test(text)) return text.slice(1);
    return Array.from(new TextEncoder().encode(text), (b) => b.toString(16).padStart(2, '0')).join('');
  }
  // The name of a unit_id as the ground shows it (bytes that are not UTF-8 as U+FFFD).
  function nameOfUnitId(unitId) {
    const bytes = new Uint8Array(unitId.length / 2);
    for (let i = 0; i < bytes.length; ++i) bytes[i] = parseInt(unitId.substr(2 * i, 2), 16);
    return new TextDecoder().decode(bytes);
  }
  return { pointsOf, unitKey, unitIdOfKey, nameOfUnitId };
}
