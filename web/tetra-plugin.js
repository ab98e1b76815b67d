// The tetra plugin for Open MCT: an object tree per unit, realtime telemetry from the ground
// station's event stream (/api/stream, server-sent events), history from /api/history, limits from
// the service's own thresholds, a unit status view (the default display: mode, link state, gyro
// states, parity/CUSUM against thresholds, sigma, attitude, events) and commands with confirmation, sent
// as the signed-in operator with the session's CSRF token.
/* exported TetraPlugin */
/* global EventSource, TetraModel */
// eslint-disable-next-line no-unused-vars
function TetraPlugin(options) {
  'use strict';
  const { pointsOf, unitKey, unitIdOfKey, nameOfUnitId } = TetraModel();
  const base = (options && options.baseUrl) || '';
  const NS = 'tetra';

  // --- the ground station's REST and stream ----------------------------------------------------
  // Without a session the ground answers 401: back to the sign-in page.
  async function apiGet(path) {
    const response = await fetch(base + path, { credentials: 'same-origin' });
    if (response.status === 401) window.location.href = base + '/login.html';
    return response;
  }
  // The signed-in operator and the session's CSRF token; read again whenever the stream (re)opens, so a
  // restarted ground station's token is the one sent.
  const session = { user: null, role: null, csrf: null, listeners: new Set() };
  async function refreshSession() {
    const response = await apiGet('/api/session');
    if (!response.ok) return;
    Object.assign(session, await response.json());
    session.listeners.forEach((l) => l());
  }
  let unitsCache = null;
  async function units() {
    if (!unitsCache) {
      const response = await apiGet('/api/units');
      unitsCache = await response.json();
      setTimeout(() => (unitsCache = null), 2000);
    }
    return unitsCache;
  }
  // A unit by its unit_id (the ground's id of its DDS key: the name may not be UTF-8, two names may look alike).
  async function unitWithId(unitId) {
    const known = (await units()).find((u) => u.unit_id === unitId);
    return known || { unit: nameOfUnitId(unitId), unit_id: unitId, gyro_count: 4 };
  }

  // One EventSource for the page; listeners by message type. The browser reconnects by itself and
  // sends Last-Event-ID, so the ground resumes the stream where it broke off.
  const listeners = { health: new Set(), attitude: new Set(), event: new Set(), link: new Set(), reset: new Set() };
  const streamState = { connected: false, listeners: new Set() };
  let source = null;
  function stream() {
    if (source) return;
    source = new EventSource(base + '/api/stream');
    for (const type of Object.keys(listeners)) {
      source.addEventListener(type, (e) => {
        const message = type === 'reset' ? {} : JSON.parse(e.data);
        listeners[type].forEach((l) => l(message));
      });
    }
    const setConnected = (c) => {
      streamState.connected = c;
      streamState.listeners.forEach((l) => l(c));
    };
    source.onopen = () => {
      setConnected(true);
      refreshSession();
    };
    source.onerror = () => setConnected(false);
  }
  function listen(type, fn) {
    stream();
    listeners[type].add(fn);
    return () => listeners[type].delete(fn);
  }

  function datum(point, message) {
    const value = point.get(message);
    const d = { utc: message.utc_ms, value: value === null || value === undefined ? NaN : value };
    if (message.sensor_time_s !== undefined) d.sensor_time = message.sensor_time_s;
    if (point.limit) d.limit = point.limit(message);
    if (point.text && value === null) d.value = 'not available';
    return d;
  }

  // --- object tree --------------------------------------------------------------------------------
  const id = (key) => ({ namespace: NS, key });
  function parseKey(key) {
    const [kind, unit, point] = key.split('~');
    return { kind, unitId: unitIdOfKey(unit || ''), point };
  }
  const objectProvider = {
    async get(identifier) {
      const key = identifier.key;
      if (key === 'units') {
        const list = await units();
        return {
          identifier,
          name: 'tetra units',
          type: 'folder',
          location: 'ROOT',
          composition: list.map((u) => id('unit~' + unitKey(u.unit_id)))
        };
      }
      const { kind, unitId, point } = parseKey(key);
      const u = await unitWithId(unitId);
      const unit = u.unit;
      if (kind === 'unit') {
        return {
          identifier,
          name: 'Unit ' + unit,
          type: 'tetra.unit',
          location: NS + ':units',
          unit,
          unitId,
          composition: pointsOf(u).map((p) => id('point~' + unitKey(unitId) + '~' + p.key))
        };
      }
      const p = pointsOf(u).find((x) => x.key === point);
      if (!p) return undefined;
      const valueMeta = {
        key: 'value',
        name: p.name,
        hints: { range: 1 }
      };
      if (p.text) {
        valueMeta.format = 'string';
      } else {
        valueMeta.format = 'float';
        if (p.units) valueMeta.unit = p.units;
      }
      return {
        identifier,
        name: p.name + ' (' + unit + ')',
        type: p.text ? 'tetra.telemetry.text' : 'tetra.telemetry',
        location: NS + ':unit~' + unitKey(unitId),
        unit,
        unitId,
        point: p.key,
        telemetry: {
          values: [
            { key: 'utc', source: 'utc', name: 'UTC (DDS source timestamp)', format: 'utc', hints: { domain: 1 } },
            { key: 'sensor_time', name: 'Sensor time', unit: 's', format: 'float', hints: { domain: 2 } },
            valueMeta
          ].concat(p.limit ? [{ key: 'limit', name: 'Limit', format: 'float' }] : [])
        }
      };
    }
  };

  function pointOf(domainObject) {
    return unitWithId(domainObject.unitId).then((u) => pointsOf(u).find((p) => p.key === domainObject.point));
  }
  const isPoint = (o) => o.type === 'tetra.telemetry' || o.type === 'tetra.telemetry.text';

  const realtimeProvider = {
    supportsSubscribe: isPoint,
    subscribe(domainObject, callback) {
      let stop = () => {};
      let cancelled = false;
      pointOf(domainObject).then((p) => {
        if (!p || cancelled) return;
        stop = listen(p.source, (m) => {
          if (m.unit_id === domainObject.unitId) callback(datum(p, m));
        });
      });
      return () => {
        cancelled = true;
        stop();
      };
    }
  };

  const historicalProvider = {
    supportsRequest: isPoint,
    async request(domainObject, opts) {
      const p = await pointOf(domainObject);
      if (!p || p.source === 'link') return [];
      const url =
        base +
        '/api/history?unit_id=' +
        domainObject.unitId +
        '&kind=' +
        p.source +
        '&start=' +
        (opts.start || 0) +
        '&end=' +
        (opts.end || Date.now()) +
        '&max=2000';
      const response = await apiGet(url.slice(base.length));
      if (!response.ok) return [];
      const rows = await response.json();
      return rows.map((m) => datum(p, m));
    }
  };

  // Limits: the service's thresholds travel with each value; beyond them the value is red.
  const limitProvider = {
    supportsLimits: (o) => isPoint(o) && ['chi2', 'cusum', 'health_age_s'].includes(o.point),
    getLimitEvaluator() {
      return {
        evaluate(d) {
          if (typeof d.value === 'number' && typeof d.limit === 'number' && d.value > d.limit) {
            return { cssClass: 'is-limit--upr is-limit--red', name: 'Above threshold' };
          }
          return undefined;
        }
      };
    },
    getLimits() {
      return { limits: () => Promise.resolve({}) };
    }
  };

  // --- commands -------------------------------------------------------------------------------------
  function operatorId() {
    return session.user || '?';
  }
  async function sendCommand(openmct, command, path) {
    try {
      if (!session.csrf) await refreshSession();
      const response = await fetch(base + (path || '/api/command'), {
        method: 'POST',
        credentials: 'same-origin',
        headers: { 'Content-Type': 'application/json', 'X-CSRF-Token': session.csrf || '' },
        body: JSON.stringify(command)
      });
      const answer = await response.json();
      if (response.status === 202) {
        // The two-person rule: a forced exclusion waits for a second commander's approval.
        openmct.notifications.info('Waiting for a second commander to approve: ' + answer.command);
      } else if (!response.ok) {
        openmct.notifications.error('Command not sent: ' + answer.error);
      } else if (answer.accepted) {
        openmct.notifications.info('Accepted: ' + answer.detail);
      } else {
        openmct.notifications.alert('Refused: ' + answer.detail);
      }
      return answer;
    } catch (err) {
      openmct.notifications.error('Command failed: ' + err);
      return { error: String(err) };
    }
  }
  function describe(command) {
    return command.action + (command.gyro ? ' gyro ' + command.gyro : '') + (command.force ? ' (FORCE)' : '');
  }
  //! Asks for confirmation naming the unit, then sends; resolves with the acknowledgement (or null when
  //! cancelled). The command names the unit by its unit_id.
  function confirmAndSend(openmct, unit, command) {
    return new Promise((resolve) => {
      const dialog = openmct.overlays.dialog({
        iconClass: command.force ? 'error' : 'alert',
        message:
          'Send "' + describe(command) + '" to unit ' + unit + ' as operator "' + operatorId() + '"?',
        buttons: [
          {
            label: 'Send command',
            emphasis: true,
            callback: async () => {
              dialog.dismiss();
              resolve(await sendCommand(openmct, command));
            }
          },
          {
            label: 'Cancel',
            callback: () => {
              dialog.dismiss();
              resolve(null);
            }
          }
        ]
      });
    });
  }

  // --- the unit status view (default display of a unit) ----------------------------------------------
  function el(tag, attrs, text) {
    const e = document.createElement(tag);
    Object.entries(attrs || {}).forEach(([k, v]) => e.setAttribute(k, v));
    if (text !== undefined) e.textContent = text;
    return e;
  }
  // Why a decision was taken: its ledger rows (docs/fdi.md, "The ledger and the arbiter"), one per line.
  function rowText(r) {
    const num = (v) => (v === null || v === undefined ? 'none' : Number(v).toPrecision(4));
    const unit = r.unit + (r.dof !== undefined ? ' (' + r.dof + ' dof)' : '');
    const limit = r.accept !== undefined ? 'accept <= ' + num(r.accept) + ', reject > ' + num(r.threshold)
      : 'threshold ' + num(r.threshold);
    return r.source + ' ' + r.hypothesis + ': ' + num(r.statistic) + ' ' + unit + ', ' + limit + ': ' + r.verdict;
  }
  function whyCell(e) {
    const td = el('td', { class: 'tetra-why' });
    if (!Array.isArray(e.ledger) || e.ledger.length === 0) return td;
    const details = el('details', {});
    const rejected = e.ledger.filter((r) => r.verdict === 'rejected').length;
    details.appendChild(el('summary', {}, e.ledger.length + ' rows, ' + rejected + ' rejected'));
    e.ledger.forEach((r) => details.appendChild(el('div', { class: 'tetra-why-row tetra-why--' + r.verdict.replace(' ', '-') }, rowText(r))));
    td.appendChild(details);
    return td;
  }
  const fmt = (v, digits) => (v === null || v === undefined || Number.isNaN(v) ? 'not available' : v.toFixed(digits));
  const utcText = (ms) => (ms ? new Date(ms).toISOString().replace('T', ' ').replace('Z', ' UTC') : '-');

  function unitView(openmct, domainObject) {
    const unit = domainObject.unit;
    const unitId = domainObject.unitId;
    const stops = [];
    let root = null;
    const state = { health: null, attitude: null, link: null, linkAt: 0, events: [], filter: '' };
    const MAX_EVENTS = 500;

    function bar(label, value, limit) {
      const row = el('div', { class: 'tetra-bar' });
      row.appendChild(el('span', { class: 'tetra-bar__label' }, label));
      const track = el('span', { class: 'tetra-bar__track' });
      const available = typeof value === 'number';
      const fraction = available && limit > 0 ? Math.min(1, value / limit) : 0;
      const fill = el('span', {
        class: 'tetra-bar__fill' + (available && value > limit ? ' tetra-bar__fill--over' : ''),
        style: 'width:' + (100 * fraction).toFixed(1) + '%'
      });
      track.appendChild(fill);
      row.appendChild(track);
      row.appendChild(el('span', { class: 'tetra-bar__value' }, fmt(value, 2) + ' / ' + fmt(limit, 2)));
      return row;
    }

    function commandButton(label, command) {
      const b = el('button', { class: 'c-button tetra-command', 'data-command': describe(command) }, label);
      b.addEventListener('click', async () => {
        const answer = await confirmAndSend(openmct, unit, command);
        if (answer && root) {
          const out = root.querySelector('#tetra-ack');
          out.textContent =
            answer.error !== undefined
              ? 'error: ' + answer.error
              : answer.pending !== undefined
                ? 'WAITING FOR APPROVAL by a second commander within ' + answer.approve_within_s + ' s'
                : (answer.accepted ? 'ACCEPTED: ' : 'REFUSED: ') + answer.detail;
          out.className = answer.accepted ? 'tetra-ack tetra-ack--ok' : 'tetra-ack tetra-ack--refused';
        }
      });
      return b;
    }

    function render() {
      if (!root) return;
      const h = state.health;
      const a = state.attitude;
      const link = state.link ? state.link.state : 'WAITING';
      const stale = link !== 'LIVE';
      const mode = h ? (h.waiting ? 'WAITING FOR GYROS' : h.mode) : 'no health yet';
      root.querySelector('#tetra-mode').textContent = mode;
      root.querySelector('#tetra-mode').className = 'tetra-mode tetra-mode--' + (h ? mode.split(' ')[0] : 'NONE');
      root.querySelector('#tetra-silences').textContent = h
        ? 'every gyro silent at once: ' + h.counters.unit_silences + ' times'
        : '';
      const linkEl = root.querySelector('#tetra-link');
      // A lost service means stale data too: both words, so STALE is always there to see.
      linkEl.textContent = link === 'SERVICE LOST' ? 'STALE \u00b7 SERVICE LOST' : link;
      linkEl.className = 'tetra-link tetra-link--' + link.replace(' ', '_');
      // Ages keep counting from the last link message, also while the ground link is lost.
      const since = (Date.now() - state.linkAt) / 1000;
      const aged = (v) => (typeof v === 'number' ? v + since : v);
      root.querySelector('#tetra-ages').textContent = state.link
        ? 'health age ' +
          fmt(aged(state.link.health_age_s), 1) +
          ' s, attitude age ' +
          fmt(aged(state.link.attitude_age_s), 1) +
          ' s (stale after ' +
          fmt(state.link.stale_after_s, 1) +
          ' s)'
        : '';
      root.classList.toggle('tetra-unit--stale', stale);
      root.querySelector('#tetra-time').textContent = h
        ? 'Health ' + utcText(h.utc_ms) + ' (sensor time ' + fmt(h.sensor_time_s, 3) + ' s)'
        : '';

      const gyros = root.querySelector('#tetra-gyros');
      // Rebuilt only when it changes (buttons stay put while an operator reaches for them).
      const gyroKey = h ? JSON.stringify([h.gyros, h.gyros_used]) : '';
      if (h && gyros.dataset.key !== gyroKey) {
        gyros.dataset.key = gyroKey;
        gyros.innerHTML = '';
        h.gyros.forEach((g) => {
          const tr = el('tr', { class: 'tetra-gyro tetra-gyro--' + g.state, 'data-gyro': String(g.id) });
          tr.appendChild(el('td', {}, String(g.id)));
          tr.appendChild(el('td', { class: 'tetra-gyro__state' }, g.state));
          tr.appendChild(el('td', {}, g.kind === 'none' ? '-' : g.kind));
          tr.appendChild(el('td', {}, h.gyros_used.includes(g.id) ? 'used' : '-'));
          const cmd = el('td');
          if (g.state === 'excluded') {
            cmd.appendChild(commandButton('Reinstate', { unit_id: unitId, action: 'reinstate', gyro: g.id }));
          } else {
            cmd.appendChild(commandButton('Exclude', { unit_id: unitId, action: 'exclude', gyro: g.id }));
            cmd.appendChild(commandButton('Exclude (force)', { unit_id: unitId, action: 'exclude', gyro: g.id, force: true }));
          }
          tr.appendChild(cmd);
          gyros.appendChild(tr);
        });
      }
      const parity = root.querySelector('#tetra-parity');
      parity.innerHTML = '';
      if (h) {
        if (h.fdi_available === false) {
          parity.appendChild(el('div', { class: 'tetra-na' }, 'fault detection NOT available: a new fault would go unseen'));
        }
        if (!h.parity_available) {
          parity.appendChild(el('div', { class: 'tetra-na' }, 'parity, chi2, CUSUM: not available (fewer than four gyros)'));
        } else {
          parity.appendChild(el('div', {}, 'parity residual ' + fmt(h.parity_residual, 2) + ' sigma'));
          parity.appendChild(bar('chi2', h.chi2, h.chi2_threshold));
          parity.appendChild(bar('CUSUM', h.cusum, h.cusum_threshold));
        }
      }
      const att = root.querySelector('#tetra-attitude');
      att.innerHTML = '';
      if (a) {
        att.appendChild(el('div', {}, 'q (w,x,y,z) = ' + a.q.map((v) => v.toFixed(6)).join(', ')));
        att.appendChild(
          el(
            'div',
            {},
            'roll ' + a.euler_deg.roll.toFixed(3) + ' deg, pitch ' + a.euler_deg.pitch.toFixed(3) + ' deg, yaw ' +
              a.euler_deg.yaw.toFixed(3) + ' deg'
          )
        );
        att.appendChild(el('div', {}, 'rate ' + a.rate_dps.map((v) => v.toFixed(4)).join(', ') + ' deg/s'));
        att.appendChild(
          el('div', { id: 'tetra-sigma' }, 'sigma ' + a.sigma_deg.map((v) => v.toFixed(4)).join(', ') + ' deg')
        );
        att.appendChild(el('div', {}, utcText(a.utc_ms) + ' (sensor time ' + a.sensor_time_s.toFixed(3) + ' s)'));
      }
      const filter = root.querySelector('#tetra-event-filter');
      const kinds = Array.from(new Set(state.events.map((e) => e.event))).sort();
      if (filter.dataset.kinds !== kinds.join(',')) {
        filter.dataset.kinds = kinds.join(',');
        filter.innerHTML = '';
        filter.appendChild(el('option', { value: '' }, 'all kinds'));
        kinds.forEach((k) => filter.appendChild(el('option', { value: k }, k)));
        filter.value = kinds.includes(state.filter) ? state.filter : '';
      }
      const events = root.querySelector('#tetra-events');
      const eventKey =
        state.filter + '/' + String(state.events.length) + '/' +
        (state.events.length ? state.events[state.events.length - 1].utc_ms : 0);
      if (events.dataset.key === eventKey) return;
      events.dataset.key = eventKey;
      events.innerHTML = '';
      state.events
        .filter((e) => !state.filter || e.event === state.filter)
        .slice(-100)
        .reverse()
        .forEach((e) => {
          const tr = el('tr', { class: 'tetra-event tetra-event--' + e.event });
          tr.appendChild(el('td', {}, utcText(e.utc_ms)));
          tr.appendChild(el('td', {}, fmt(e.sensor_time_s, 3)));
          tr.appendChild(el('td', {}, e.event));
          tr.appendChild(el('td', {}, e.gyro ? String(e.gyro) : '-'));
          let detail = e.detail || e.kind || e.test || '';
          if (e.operator) detail += ' [' + e.operator + ' @ ' + e.origin + (e.accepted ? ', accepted' : ', refused') + ']';
          tr.appendChild(el('td', {}, detail));
          tr.appendChild(whyCell(e));
          events.appendChild(tr);
        });
    }

    function skeleton() {
      const r = el('div', { class: 'tetra-unit', 'data-unit': unit });
      r.innerHTML =
        '<div class="tetra-head"><span class="tetra-name"></span>' +
        '<span id="tetra-mode" class="tetra-mode"></span><span id="tetra-link" class="tetra-link"></span>' +
        '<span id="tetra-ages" class="tetra-ages"></span></div>' +
        '<div id="tetra-time" class="tetra-time"></div><div id="tetra-silences" class="tetra-time"></div>' +
        '<div class="tetra-grid"><section><h2>Gyros</h2><table class="tetra-table"><thead><tr><th>gyro</th>' +
        '<th>state</th><th>fault</th><th>solution</th><th>command</th></tr></thead><tbody id="tetra-gyros"></tbody>' +
        '</table><div class="tetra-commands"></div><div id="tetra-ack" class="tetra-ack"></div>' +
        '<div id="tetra-pending" class="tetra-pending"></div>' +
        '<div>signed in as <span id="tetra-operator" class="tetra-operator"></span>' +
        ' <button id="tetra-sign-out" class="c-button">Sign out</button></div></section>' +
        '<section><h2>Parity and CUSUM</h2><div id="tetra-parity"></div><h2>Attitude</h2>' +
        '<div id="tetra-attitude"></div></section></div>' +
        '<section><div class="tetra-events-head"><h2>FDI events</h2><label>kind ' +
        '<select id="tetra-event-filter"></select></label></div>' +
        '<table class="tetra-table"><thead><tr><th>UTC</th><th>sensor time [s]</th>' +
        '<th>event</th><th>gyro</th><th>detail</th><th>why (ledger)</th></tr></thead><tbody id="tetra-events"></tbody></table></section>';
      r.querySelector('.tetra-name').textContent = 'Unit ' + unit;
      r.querySelector('.tetra-commands').appendChild(commandButton('FDI reset', { unit_id: unitId, action: 'reset' }));
      const showOperator = () => {
        r.querySelector('#tetra-operator').textContent = session.user ? session.user + ' (' + session.role + ')' : '?';
      };
      session.listeners.add(showOperator);
      stops.push(() => session.listeners.delete(showOperator));
      showOperator();
      r.querySelector('#tetra-event-filter').addEventListener('change', (e) => {
        state.filter = e.target.value;
        render();
      });
      r.querySelector('#tetra-sign-out').addEventListener('click', async () => {
        await fetch(base + '/api/logout', {
          method: 'POST',
          credentials: 'same-origin',
          headers: { 'Content-Type': 'application/json', 'X-CSRF-Token': session.csrf || '' },
          body: '{}'
        });
        window.location.href = base + '/login.html';
      });
      return r;
    }

    return {
      show(element) {
        root = skeleton();
        element.appendChild(root);
        stops.push(
          listen('health', (m) => {
            if (m.unit_id !== unitId) return;
            state.health = m;
            render();
            // Latency from the service's write (DDS source timestamp) to this display, for
            // bench/ground_latency.py (same host, same clock); the newest 10000.
            const lat = (window.tetraHealthLatencyMs = window.tetraHealthLatencyMs || []);
            lat.push(Date.now() - m.utc_ms);
            if (lat.length > 10000) lat.shift();
          })
        );
        stops.push(listen('attitude', (m) => m.unit_id === unitId && ((state.attitude = m), render())));
        stops.push(
          listen('link', (m) => {
            if (m.unit_id !== unitId) return;
            state.link = m;
            state.linkAt = Date.now();
            render();
          })
        );
        const ticker = setInterval(render, 500);
        stops.push(() => clearInterval(ticker));
        // Commands of this unit waiting for a second commander: another commander may approve them.
        const showPending = async () => {
          const response = await apiGet('/api/pending');
          if (!response.ok || !root) return;
          const box = root.querySelector('#tetra-pending');
          box.innerHTML = '';
          for (const p of (await response.json()).filter((x) => x.unit_id === unitId)) {
            const line = el('div', { class: 'tetra-pending-item' });
            line.appendChild(el('span', {}, p.operator + ' asks: ' + p.command + ' (' + Math.ceil(p.expires_in_s) + ' s left) '));
            if (session.role === 'commander' && p.operator !== session.user) {
              const b = el('button', { class: 'c-button tetra-approve' }, 'Approve');
              b.addEventListener('click', async () => {
                const answer = await sendCommand(openmct, { id: p.id }, '/api/approve');
                if (answer && root) root.querySelector('#tetra-ack').textContent = answer.error !== undefined
                  ? 'error: ' + answer.error
                  : (answer.accepted ? 'ACCEPTED: ' : 'REFUSED: ') + answer.detail + ' (approved by ' + operatorId() + ')';
              });
              line.appendChild(b);
            }
            box.appendChild(line);
          }
        };
        const pendingTicker = setInterval(showPending, 2000);
        stops.push(() => clearInterval(pendingTicker));
        stops.push(
          listen('event', (m) => {
            if (m.unit_id !== unitId) return;
            state.events.push(m);
            if (state.events.length > MAX_EVENTS) state.events.shift();
            render();
          })
        );
        const lost = (connected) => {
          if (!connected && root) {
            state.link = Object.assign({}, state.link || {}, { state: 'GROUND LINK LOST' });
            render();
          }
        };
        streamState.listeners.add(lost);
        stops.push(() => streamState.listeners.delete(lost));
        // The event history; again after a reset of the stream (a restarted ground station, a gap).
        const loadEvents = () =>
          apiGet('/api/history?unit_id=' + unitId + '&kind=event&max=' + MAX_EVENTS)
            .then((r) => (r.ok ? r.json() : []))
            .then((rows) => {
              const seen = new Set(state.events.map((e) => e.event_seq + '/' + e.utc_ms));
              state.events = rows.filter((e) => !seen.has(e.event_seq + '/' + e.utc_ms)).concat(state.events);
              state.events.sort((x, y) => x.utc_ms - y.utc_ms);
              if (state.events.length > MAX_EVENTS) state.events = state.events.slice(-MAX_EVENTS);
              render();
            });
        stops.push(listen('reset', loadEvents));
        loadEvents();
        render();
      },
      destroy() {
        stops.forEach((s) => s());
        root = null;
      }
    };
  }

  return function install(openmct) {
    refreshSession();
    openmct.objects.addRoot(id('units'), openmct.priority.HIGH);
    openmct.objects.addProvider(NS, objectProvider);
    openmct.types.addType('tetra.unit', {
      name: 'tetra unit',
      description: 'A redundant gyro package and its fusion service',
      cssClass: 'icon-telemetry'
    });
    openmct.types.addType('tetra.telemetry', { name: 'tetra telemetry', cssClass: 'icon-telemetry' });
    openmct.types.addType('tetra.telemetry.text', { name: 'tetra state', cssClass: 'icon-telemetry' });
    openmct.telemetry.addProvider(realtimeProvider);
    openmct.telemetry.addProvider(historicalProvider);
    openmct.telemetry.addProvider(limitProvider);
    openmct.objectViews.addProvider({
      key: 'tetra.unit-status',
      name: 'Unit status',
      cssClass: 'icon-layout',
      canView: (o) => o.type === 'tetra.unit',
      view: (o) => unitView(openmct, o),
      priority: () => openmct.priority.HIGH
    });
    openmct.actions.register({
      key: 'tetra.fdi-reset',
      name: 'FDI reset (tetra)',
      cssClass: 'icon-refresh',
      group: 'action',
      appliesTo: (objectPath) => objectPath[0] && objectPath[0].type === 'tetra.unit',
      invoke: (objectPath) =>
        confirmAndSend(openmct, objectPath[0].unit, { unit_id: objectPath[0].unitId, action: 'reset' })
    });
  };
}
