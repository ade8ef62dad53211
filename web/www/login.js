// The login form: POST /api/login with JSON; cncd-web answers with the session cookie, and the
// dashboard at / takes over. A refusal (wrong password, too many attempts) is shown as given.

const form = document.getElementById('login-form');
const error = document.getElementById('login-error');
const submit = document.getElementById('login-submit');

form.addEventListener('submit', async (event) => {
  event.preventDefault();
  error.textContent = '';
  submit.disabled = true;
  const user = document.getElementById('login-user').value;
  const password = document.getElementById('login-password').value;
  try {
    const response = await fetch('/api/login', {
      method: 'POST',
      credentials: 'same-origin',
      headers: {'Content-Type': 'application/json'},
      body: JSON.stringify({user, password}),
    });
    if (response.ok) {
      location.href = '/';
      return;
    }
    let reason = '';
    try {
      reason = (await response.json()).error ?? '';
    } catch {
      // no JSON body: the status says it
    }
    if (response.status === 429) {
      const wait = response.headers.get('Retry-After');
      reason ||= 'too many attempts';
      if (wait) reason += `: try again in ${wait} s`;
    }
    error.textContent = reason ||
        (response.status === 401 ? 'wrong user name or password' : `HTTP ${response.status}`);
  } catch (e) {
    error.textContent = `cannot reach cncd-web: ${e.message}`;
  } finally {
    submit.disabled = false;
  }
});
