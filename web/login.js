// Sign-in of the tetra ground page: the password goes as JSON to /api/login, which sets the session
// cookie (HttpOnly, SameSite=Strict); then the application.
(function () {
  'use strict';
  const form = document.getElementById('tetra-login-form');
  const error = document.getElementById('tetra-login-error');
  form.addEventListener('submit', async (e) => {
    e.preventDefault();
    error.textContent = '';
    try {
      const response = await fetch('/api/login', {
        method: 'POST',
        headers: { 'Content-Type': 'application/json' },
        body: JSON.stringify({
          user: document.getElementById('tetra-user').value,
          password: document.getElementById('tetra-password').value
        })
      });
      const answer = await response.json();
      if (response.ok) {
        window.location.href = '/';
      } else {
        error.textContent = answer.error || 'sign-in failed';
      }
    } catch (err) {
      error.textContent = 'the ground station does not answer: ' + err;
    }
  });
})();
