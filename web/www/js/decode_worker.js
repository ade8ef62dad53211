// Parses large JSON-RPC frames off the page's thread (a toolpath preview is several MiB) and
// decodes a preview's polylines there too; the typed arrays are transferred, not copied, back.

import {decodeInPlace} from './preview_decode.js';

self.addEventListener('message', (event) => {
  let message;
  try {
    message = JSON.parse(event.data);
  } catch (e) {
    self.postMessage(
        {jsonrpc: '2.0', method: 'error', params: {message: `frame is not JSON: ${e}`}});
    return;
  }
  const result = message?.result;
  if (!result || typeof result.xyz !== 'string') {
    self.postMessage(message);
    return;
  }
  try {
    const decoded = decodeInPlace(result).decoded;
    self.postMessage(message, [
      decoded.positions.buffer, decoded.colors.buffer, decoded.segLine.buffer,
      decoded.segKind.buffer
    ]);
  } catch (e) {
    self.postMessage({
      jsonrpc: '2.0',
      id: message.id,
      error: {code: -1, message: `the preview could not be decoded: ${e}`}
    });
  }
});
