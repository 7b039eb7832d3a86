// Vite build of the Scene Viewer front end: one page per window (viewer, Joint Move, QMotor, Teachpendant).
import { resolve } from 'node:path';
import { defineConfig } from 'vite';

export default defineConfig({
  base: './',
  build: {
    target: 'es2020',
    chunkSizeWarningLimit: 1024,
    rollupOptions: {
      input: {
        index: resolve(__dirname, 'index.html'),
        jointmove: resolve(__dirname, 'jointmove.html'),
        qmotor: resolve(__dirname, 'qmotor.html'),
        teachpendant: resolve(__dirname, 'teachpendant.html'),
      },
    },
  },
});
