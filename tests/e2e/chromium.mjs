// The browser every Chromium test of the project launches: Debian's
// chromium (scripts/setup.sh browser; CHROMIUM overrides the path), headless,
// with the flags this closed network needs (without the background-networking
// ones Chromium keeps trying to reach Google's hosts) and software WebGL.
export const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
export const FLAGS = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--enable-unsafe-swiftshader',
];
