// The tetra ground application: Open MCT with UTC time, a realtime conductor and the tetra plugin.
/* global openmct, TetraPlugin */
(function () {
  const FIFTEEN_MINUTES_MS = 15 * 60 * 1000;
  openmct.setAssetPath('openmct');
  openmct.install(openmct.plugins.LocalStorage());
  openmct.install(openmct.plugins.MyItems());
  openmct.install(openmct.plugins.UTCTimeSystem());
  openmct.install(openmct.plugins.Espresso());
  openmct.install(openmct.plugins.DisplayLayout());
  openmct.install(
    openmct.plugins.Conductor({
      menuOptions: [
        {
          name: 'Realtime',
          timeSystem: 'utc',
          clock: 'local',
          clockOffsets: { start: -FIFTEEN_MINUTES_MS, end: 5000 }
        },
        {
          name: 'Fixed',
          timeSystem: 'utc',
          bounds: { start: Date.now() - FIFTEEN_MINUTES_MS, end: Date.now() }
        }
      ]
    })
  );
  openmct.install(TetraPlugin({ baseUrl: '' }));
  openmct.start();
})();
