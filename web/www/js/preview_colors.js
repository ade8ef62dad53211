// Colours of the toolpath preview, by kind of move, as 0..1 RGB; shared by the decode worker
// and the page.

const kColors = {
  rapid: [0.95, 0.6, 0.15],
  feed: [0.35, 0.85, 1.0],
  arc: [0.45, 0.65, 1.0],
  cycle: [0.95, 0.4, 0.9],
  probe: [0.45, 1.0, 0.45],
};

// The part of the path already run: grey, whatever its kind.
export const kDoneColor = [0.42, 0.42, 0.46];

export function kindColor(kind) { return kColors[kind] ?? kColors.feed; }

export function kindCss(kind) {
  const [r, g, b] = kindColor(kind);
  return `rgb(${Math.round(r * 255)}, ${Math.round(g * 255)}, ${Math.round(b * 255)})`;
}
