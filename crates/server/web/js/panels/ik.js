// IK panel: the target's position comes from the scene's `target` dummy; Move sends the
// IK packet a TCP client would send.

import { S } from '../state.js';
import { $, setReply } from '../dom.js';
import { send } from '../net.js';

export function prefillIk() {
  const p = S.objects[S.ikTarget].pose;
  $('ik-tx').value = p[0].toFixed(3);
  $('ik-ty').value = p[1].toFixed(3);
  $('ik-tz').value = p[2].toFixed(3);
  S.ikPrefilled = true;
}
$('ik-form').addEventListener('submit', (e) => {
  e.preventDefault();
  const v = ['ik-tx', 'ik-ty', 'ik-tz'].map((id) => parseFloat($(id).value));
  if (v.some((x) => !Number.isFinite(x))) return;
  send({ op: 'packet', text: `<IK#TX=${v[0]},TY=${v[1]},TZ=${v[2]}>` }, (r) => setReply($('ik-reply'), r));
});
