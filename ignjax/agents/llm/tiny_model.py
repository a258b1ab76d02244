"""A tiny, randomly initialised Qwen2-VL-style model folder for tests.

``python -m ignjax.agents.llm.tiny_model DIR [--seed S]`` (or, where the
``ignjax`` package's own dependencies are not installed, as in the vLLM server
environment: ``python -P path/to/ignjax/agents/llm/tiny_model.py DIR``) writes
a complete Hugging Face model folder that vLLM (and transformers) load with no
download:

- ``config.json``: a Qwen2-VL config (``Qwen2VLForConditionalGeneration``) in
  the flat layout of the published Qwen2-VL checkpoints: text hidden size 128,
  2 layers, 2 attention heads / 1 KV head, mrope section [8, 12, 12],
  vocabulary 2,048, tied embeddings; vision tower of depth 1, width 64,
  2 heads, patch 14, spatial merge 2 (about 0.8 M parameters in all);
- ``model.safetensors``: bfloat16 weights drawn from ``--seed`` (normal with
  std 0.02 for matrices, ones for norm scales, zeros for biases), in the
  tensor names transformers 5 writes (``model.language_model.*``,
  ``model.visual.*``);
- ``tokenizer.json`` / ``tokenizer_config.json``: a byte-level BPE tokenizer
  with Qwen2's pre-tokenizer, trained here on a fixed generated corpus, plus
  Qwen's special tokens (``<|endoftext|>``, ``<|im_start|>``, ``<|im_end|>``,
  ``<|vision_start|>``, ``<|image_pad|>`` ...) as the last ids, and Qwen2-VL's
  chat template;
- ``preprocessor_config.json``: Qwen2-VL's image processor, at most
  ``MAX_PIXELS`` pixels (256 visual tokens) per image;
- ``generation_config.json``: end-of-turn ids only (no sampling defaults);
- ``tiny_model.json``: the seed and ``FORMAT_VERSION`` it was written with.

The same seed gives the same bytes (the tokenizer does not depend on the
seed). The folder is written beside ``DIR`` under a temporary name and then
renamed into place, so a reader never sees half a model.

It needs torch, transformers, safetensors and tokenizers, which are not
ignjax dependencies: run it with the vLLM server environment's python (see
``.ci/prepare-vllm``). Those are imported inside the functions, so this module
imports anywhere. It imports nothing from ignjax, so it also runs as a plain
file by path (``-P`` keeps its own folder off ``sys.path``), which is how
``.ci/prepare-vllm`` runs it: ``python -m`` would import ``ignjax.agents``,
whose ``__init__`` needs jax, absent from the server environment.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import sys
from pathlib import Path

# Special tokens, in Qwen2-VL's order; they take the last ids of the vocabulary.
SPECIAL_TOKENS = (
    "<|endoftext|>",
    "<|im_start|>",
    "<|im_end|>",
    "<|object_ref_start|>",
    "<|object_ref_end|>",
    "<|box_start|>",
    "<|box_end|>",
    "<|quad_start|>",
    "<|quad_end|>",
    "<|vision_start|>",
    "<|vision_end|>",
    "<|vision_pad|>",
    "<|image_pad|>",
    "<|video_pad|>",
)
FORMAT_VERSION = 1  # bump when the folder's content changes for a given seed
VOCAB_SIZE = 2048
MIN_PIXELS = 56 * 56  # 4 visual tokens
MAX_PIXELS = 256 * 28 * 28  # 200,704 pixels: 256 visual tokens
MAX_POSITION_EMBEDDINGS = 32768
INIT_STD = 0.02

# Qwen2's pre-tokenizer split (transformers' tokenization_qwen2.PRETOKENIZE_REGEX).
PRETOKENIZE_REGEX = (
    r"""(?i:'s|'t|'re|'ve|'m|'ll|'d)|[^\r\n\p{L}\p{N}]?\p{L}+|\p{N}| ?[^\s\p{L}\p{N}]+[\r\n]*|\s*[\r\n]+|\s+(?!\S)|\s+"""
)

# Qwen2-VL-Instruct's chat template (images and videos as
# <|vision_start|><|image_pad|><|vision_end|>, a default system message).
CHAT_TEMPLATE = (
    "{% set image_count = namespace(value=0) %}{% set video_count = namespace(value=0) %}"
    "{% for message in messages %}{% if loop.first and message['role'] != 'system' %}"
    "<|im_start|>system\nYou are a helpful assistant.<|im_end|>\n{% endif %}"
    "<|im_start|>{{ message['role'] }}\n"
    "{% if message['content'] is string %}{{ message['content'] }}<|im_end|>\n"
    "{% else %}{% for content in message['content'] %}"
    "{% if content['type'] == 'image' or 'image' in content or 'image_url' in content %}"
    "{% set image_count.value = image_count.value + 1 %}"
    "{% if add_vision_id %}Picture {{ image_count.value }}: {% endif %}"
    "<|vision_start|><|image_pad|><|vision_end|>"
    "{% elif content['type'] == 'video' or 'video' in content %}"
    "{% set video_count.value = video_count.value + 1 %}"
    "{% if add_vision_id %}Video {{ video_count.value }}: {% endif %}"
    "<|vision_start|><|video_pad|><|vision_end|>"
    "{% elif 'text' in content %}{{ content['text'] }}{% endif %}{% endfor %}<|im_end|>\n"
    "{% endif %}{% endfor %}"
    "{% if add_generation_prompt %}<|im_start|>assistant\n{% endif %}"
)

TEXT_CONFIG = {
    "hidden_size": 128,
    "intermediate_size": 256,
    "num_hidden_layers": 2,
    "num_attention_heads": 2,
    "num_key_value_heads": 1,
    "hidden_act": "silu",
    "rms_norm_eps": 1e-6,
    "rope_theta": 1000000.0,
    "rope_scaling": {"type": "mrope", "mrope_section": [8, 12, 12]},  # sums to head_dim / 2 = 32
}
VISION_CONFIG = {
    "depth": 1,
    "embed_dim": 64,
    "hidden_size": 128,  # the merger's output width = the text hidden size
    "hidden_act": "quick_gelu",
    "mlp_ratio": 4,
    "num_heads": 2,
    "in_chans": 3,
    "patch_size": 14,
    "spatial_patch_size": 14,
    "spatial_merge_size": 2,
    "temporal_patch_size": 2,
}

# Words the fixed tokenizer-training corpus is drawn from (navigation talk,
# JSON-ish answers and common English), so that merges fill the vocabulary.
_WORDS = """
the a an and or but not of to in on at by for with from into onto over under
above below behind between near far left right front back up down north south
east west room kitchen bedroom bathroom living hallway corridor office garage
door window wall floor ceiling stairs table chair bed sofa couch desk shelf
cabinet lamp plant picture painting mirror television laptop book cup bottle
toilet sink oven fridge counter rug pillow towel clock vase box basket bag
move stop ask turn go walk look see find search explore reach goal target
object instance agent answer question cost step action direction cell grid
map view image camera frame scene episode navigation position distance metre
meters one two three four five six seven eight nine ten zero first second
third last next previous same different other this that these those there
here where what which who how why when yes no maybe please thank you is are
was were be been being have has had do does did can could should would will
it its they them their we our he she his her i me my your image picture
red green blue yellow black white gray brown orange purple pink small large
big little tall short wide narrow open closed wooden metal glass soft hard
system user assistant helpful respond only json with keys value values type
string integer number boolean true false null array object enum minimum
maximum required properties schema description choose select output reply
""".split()


def training_corpus() -> list[str]:
    """A fixed, generated text corpus (independent of the model seed): the
    words above plus made-up words of 2 to 4 syllables, so that the trainer
    finds enough merges to fill the vocabulary exactly."""
    rng = random.Random(20240917)
    onsets = ["", "b", "d", "f", "g", "k", "l", "m", "n", "p", "r", "s", "t", "v", "z", "sh", "ch", "tr", "st"]
    vowels = ["a", "e", "i", "o", "u", "ai", "ou"]
    codas = ["", "", "n", "r", "s", "l", "m", "k"]
    made_up = sorted(
        {"".join(rng.choice(onsets) + rng.choice(vowels) + rng.choice(codas) for _ in range(rng.randint(2, 4))) for _ in range(1500)}
    )
    vocabulary = _WORDS + made_up
    lines: list[str] = []
    for _ in range(12000):
        n = rng.randint(4, 14)
        words = [rng.choice(vocabulary) for _ in range(n)]
        if rng.random() < 0.3:
            words[0] = words[0].capitalize()
        sep = rng.choice([".", "?", "!", ",", ":", ";"])
        lines.append(" ".join(words) + sep)
    for _ in range(1500):
        action = rng.choice(["ask", "move", "stop"])
        lines.append(
            json.dumps(
                {
                    "action": action,
                    "direction": rng.randint(0, 7),
                    "cell": rng.randint(1, 64),
                    "question": " ".join(rng.choice(_WORDS) for _ in range(rng.randint(2, 6))),
                }
            )
        )
    lines.append(" ".join(str(i) for i in range(1000)))
    return lines


def build_tokenizer():
    """Train the byte-level BPE tokenizer; returns a ``tokenizers.Tokenizer``."""
    from tokenizers import AddedToken, Regex, Tokenizer, decoders, normalizers, pre_tokenizers, processors, trainers
    from tokenizers.models import BPE

    tok = Tokenizer(BPE(unk_token=None, continuing_subword_prefix="", end_of_word_suffix="", fuse_unk=False, byte_fallback=False))
    tok.normalizer = normalizers.NFC()
    tok.pre_tokenizer = pre_tokenizers.Sequence(
        [
            pre_tokenizers.Split(Regex(PRETOKENIZE_REGEX), behavior="isolated", invert=False),
            pre_tokenizers.ByteLevel(add_prefix_space=False, use_regex=False),
        ]
    )
    tok.decoder = decoders.ByteLevel()
    tok.post_processor = processors.ByteLevel(trim_offsets=False)
    trainer = trainers.BpeTrainer(
        vocab_size=VOCAB_SIZE - len(SPECIAL_TOKENS),
        min_frequency=2,
        show_progress=False,
        initial_alphabet=pre_tokenizers.ByteLevel.alphabet(),
        special_tokens=[],
    )
    tok.train_from_iterator(training_corpus(), trainer=trainer)
    tok.add_special_tokens([AddedToken(t, special=True, normalized=False) for t in SPECIAL_TOKENS])
    size = tok.get_vocab_size(with_added_tokens=True)
    if size > VOCAB_SIZE:
        raise RuntimeError(f"tokenizer has {size} tokens, more than the model's {VOCAB_SIZE}")
    return tok


def token_ids(tok) -> dict[str, int]:
    ids = {t: tok.token_to_id(t) for t in SPECIAL_TOKENS}
    missing = [t for t, i in ids.items() if i is None]
    if missing:
        raise RuntimeError(f"special tokens missing from the tokenizer: {missing}")
    return ids


def model_config(ids: dict[str, int]) -> dict:
    """config.json's content (the flat layout of the published checkpoints)."""
    return {
        "architectures": ["Qwen2VLForConditionalGeneration"],
        "model_type": "qwen2_vl",
        "attention_dropout": 0.0,
        "bos_token_id": ids["<|endoftext|>"],
        "eos_token_id": ids["<|im_end|>"],
        "pad_token_id": ids["<|endoftext|>"],
        "vision_start_token_id": ids["<|vision_start|>"],
        "vision_end_token_id": ids["<|vision_end|>"],
        "vision_token_id": ids["<|vision_pad|>"],
        "image_token_id": ids["<|image_pad|>"],
        "video_token_id": ids["<|video_pad|>"],
        **{k: v for k, v in TEXT_CONFIG.items()},
        "initializer_range": INIT_STD,
        "max_position_embeddings": MAX_POSITION_EMBEDDINGS,
        "max_window_layers": TEXT_CONFIG["num_hidden_layers"],
        "sliding_window": MAX_POSITION_EMBEDDINGS,
        "use_sliding_window": False,
        "tie_word_embeddings": True,
        "torch_dtype": "bfloat16",
        "use_cache": True,
        "vocab_size": VOCAB_SIZE,
        "vision_config": dict(VISION_CONFIG),
    }


def tokenizer_config(ids: dict[str, int]) -> dict:
    return {
        "add_bos_token": False,
        "add_prefix_space": False,
        "added_tokens_decoder": {
            str(ids[t]): {
                "content": t,
                "lstrip": False,
                "normalized": False,
                "rstrip": False,
                "single_word": False,
                "special": True,
            }
            for t in SPECIAL_TOKENS
        },
        "additional_special_tokens": ["<|im_start|>", "<|im_end|>", "<|vision_start|>", "<|vision_end|>", "<|vision_pad|>", "<|image_pad|>", "<|video_pad|>"],
        "bos_token": None,
        "chat_template": CHAT_TEMPLATE,
        "clean_up_tokenization_spaces": False,
        "eos_token": "<|im_end|>",
        "errors": "replace",
        "model_max_length": MAX_POSITION_EMBEDDINGS,
        "pad_token": "<|endoftext|>",
        "padding_side": "left",
        "split_special_tokens": False,
        "tokenizer_class": "Qwen2Tokenizer",
        "unk_token": None,
    }


def preprocessor_config() -> dict:
    return {
        "do_convert_rgb": True,
        "do_normalize": True,
        "do_rescale": True,
        "do_resize": True,
        "image_mean": [0.48145466, 0.4578275, 0.40821073],
        "image_std": [0.26862954, 0.26130258, 0.27577711],
        "image_processor_type": "Qwen2VLImageProcessor",
        "merge_size": VISION_CONFIG["spatial_merge_size"],
        "min_pixels": MIN_PIXELS,
        "max_pixels": MAX_PIXELS,
        "patch_size": VISION_CONFIG["patch_size"],
        "processor_class": "Qwen2VLProcessor",
        "resample": 3,
        "rescale_factor": 1 / 255,
        "size": {"shortest_edge": MIN_PIXELS, "longest_edge": MAX_PIXELS},
        "temporal_patch_size": VISION_CONFIG["temporal_patch_size"],
    }


def generation_config(ids: dict[str, int]) -> dict:
    return {
        "bos_token_id": ids["<|endoftext|>"],
        "eos_token_id": [ids["<|im_end|>"], ids["<|endoftext|>"]],
        "pad_token_id": ids["<|endoftext|>"],
    }


def random_weights(config: dict, seed: int) -> dict:
    """Name -> bfloat16 tensor, in the names and shapes transformers gives
    ``Qwen2VLForConditionalGeneration`` for ``config``; values depend only on
    ``seed`` (drawn in sorted name order from one CPU generator)."""
    import torch
    from transformers import Qwen2VLConfig, Qwen2VLForConditionalGeneration

    cfg = Qwen2VLConfig(**config)
    with torch.device("meta"):
        skeleton = Qwen2VLForConditionalGeneration(cfg)
    shapes = {name: tuple(t.shape) for name, t in skeleton.state_dict().items()}
    if config.get("tie_word_embeddings"):
        shapes.pop("lm_head.weight", None)
    gen = torch.Generator(device="cpu").manual_seed(int(seed))
    out = {}
    for name in sorted(shapes):
        shape = shapes[name]
        module = name.split(".")[-2]  # norm1, ln_q, input_layernorm, norm ...
        is_norm = module.startswith(("norm", "ln_")) or module.endswith("norm")
        if name.endswith(".bias"):
            t = torch.zeros(shape)
        elif is_norm:
            t = torch.ones(shape)
        else:
            t = torch.randn(shape, generator=gen) * INIT_STD
        out[name] = t.to(torch.bfloat16).contiguous()
    return out


def _json_bytes(obj: dict) -> bytes:
    return (json.dumps(obj, indent=2, sort_keys=True, ensure_ascii=False) + "\n").encode("utf-8")


def write_model(out_dir: str | os.PathLike, seed: int = 0) -> Path:
    """Write the model folder to ``out_dir`` (replacing one already there)."""
    from safetensors.torch import save_file

    out = Path(out_dir).resolve()
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp-{os.getpid()}")
    old = out.with_name(f".{out.name}.old-{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir()
    try:
        tok = build_tokenizer()
        ids = token_ids(tok)
        config = model_config(ids)
        (tmp / "tokenizer.json").write_text(tok.to_str(pretty=True) + "\n", encoding="utf-8")
        (tmp / "tokenizer_config.json").write_bytes(_json_bytes(tokenizer_config(ids)))
        (tmp / "config.json").write_bytes(_json_bytes(config))
        (tmp / "preprocessor_config.json").write_bytes(_json_bytes(preprocessor_config()))
        (tmp / "generation_config.json").write_bytes(_json_bytes(generation_config(ids)))
        # One metadata key only: safetensors writes a map's keys in no fixed order.
        save_file(random_weights(config, seed), str(tmp / "model.safetensors"), metadata={"format": "pt"})
        (tmp / "model.safetensors").chmod(0o644)
        (tmp / "tiny_model.json").write_bytes(_json_bytes({"generator": "ignjax.agents.llm.tiny_model", "format": FORMAT_VERSION, "seed": int(seed)}))
        if out.exists():
            os.replace(out, old)
        os.replace(tmp, out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        shutil.rmtree(old, ignore_errors=True)
    return out


def _missing_dependencies() -> list[str]:
    import importlib.util

    return [m for m in ("torch", "transformers", "safetensors", "tokenizers") if importlib.util.find_spec(m) is None]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m ignjax.agents.llm.tiny_model",
        description="Write a tiny randomly initialised Qwen2-VL-style model folder (same seed, same bytes).",
    )
    parser.add_argument("dir", help="output folder (replaced if it exists)")
    parser.add_argument("--seed", type=int, default=0, help="seed for the random weights (default 0)")
    args = parser.parse_args(argv)
    missing = _missing_dependencies()
    if missing:
        home = os.environ.get("IGNJAX_VLLM_HOME") or os.path.join(os.path.expanduser("~"), ".cache", "ignjax", "vllm")
        print(
            f"tiny_model: {', '.join(missing)} not importable here; run this with the server environment's python: "
            f"{home}/venv/bin/python -P {Path(__file__).resolve()} {args.dir} (prepared by .ci/prepare-vllm)",
            file=sys.stderr,
        )
        return 2
    out = write_model(args.dir, seed=args.seed)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
